"""Robot and world models (URDF/SDF), installed as package data of `harness`."""
