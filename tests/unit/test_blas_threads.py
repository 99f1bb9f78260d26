"""Importing clearsim before numpy keeps OpenBLAS to one thread (clearsim/__init__.py): the small SVDs and
eigenproblems of the assembly and the mode report otherwise wake threads that spin against the kernels on a busy
machine. A value the user set is kept."""

import os
import subprocess
import sys


def blas_threads_after_import(environment: dict) -> str:
    code = "import clearsim, os, numpy; print(os.environ.get('OPENBLAS_NUM_THREADS'))"
    return subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True,
                          check=True).stdout.strip()


def test_importing_clearsim_first_sets_one_blas_thread():
    environment = {key: value for key, value in os.environ.items() if key != "OPENBLAS_NUM_THREADS"}
    assert blas_threads_after_import(environment) == "1"


def test_a_thread_count_the_user_set_is_kept():
    assert blas_threads_after_import(os.environ | {"OPENBLAS_NUM_THREADS": "2"}) == "2"
