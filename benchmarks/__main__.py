import sys

from benchmarks.suite import main

if __name__ == "__main__":  # importing the module (a spawned worker, a tool) must not run the suite
    sys.exit(main())
