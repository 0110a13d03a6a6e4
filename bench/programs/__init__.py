"""NC programs the benchmarks run that are made by a generator (``cam_finish``)."""
