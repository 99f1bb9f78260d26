"""clearsim benchmarks: `python -m benchmarks --help`. Not part of the tests."""
