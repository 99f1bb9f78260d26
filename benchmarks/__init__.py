"""clearsim benchmarks: `python -m benchmarks --help`. Not part of the tests."""
import clearsim  # noqa: E402,F401  (before numpy: its OpenBLAS thread setting)
