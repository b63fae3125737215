"""Running a lint: the pipeline (request in, outcome out), file discovery,
roots, worker processes, baselines, per-path ignores and the Python API."""
