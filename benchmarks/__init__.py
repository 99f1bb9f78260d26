"""clearsim benchmarks (issue #6): `python -m benchmarks --help`. Not part of the tests."""
