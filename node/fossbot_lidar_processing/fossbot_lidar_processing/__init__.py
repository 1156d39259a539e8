"""FOSSBot Lab 07 reference solution: LIDAR obstacle status and warning."""
