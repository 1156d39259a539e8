"""Many runs beyond one process: a Dask cluster, embedded or the user's.

``open_client`` gives a ``distributed.Client``: by default on an embedded
LocalCluster sized to this machine (one single-threaded worker process per
core, started and stopped with the command), or on an existing cluster
(``--scheduler tcp://HOST:8786``, started with Dask's own ``dask scheduler``
and ``dask worker``). Each task runs its node in its own process group and
ROS domain on its worker: domains are reserved per host with file locks, so
they stay unique however many workers share a machine.
"""
