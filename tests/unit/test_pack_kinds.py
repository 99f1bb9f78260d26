"""The kernels' arrays are packed by an entry point kept per the arrays' kinds (assembly/arrays.field_kinds): two
field tuples of one kind must be of one numba type, or a kept entry point would unbox arrays of another type."""

import itertools

import numpy as np
from numba import typeof

from clearsim.assembly.arrays import field_kinds


def array_variants() -> list[np.ndarray]:
    """Arrays that differ in each thing numba's typeof reads: dtype, dimensions, layout, writeable, aligned."""
    variants = []
    for dtype, shape in itertools.product((np.float64, np.int64, np.float32), ((4,), (3, 4), (2, 3, 4))):
        base = np.zeros(shape, dtype)
        variants += [base, np.asfortranarray(base), base[..., ::2]]
        readonly = base.copy()
        readonly.flags.writeable = False
        variants.append(readonly)
    buffer = np.zeros(8 * 5 + 1, np.uint8)
    variants.append(buffer[1:].view(np.float64))  # unaligned
    return variants


def test_arrays_of_one_kind_are_of_one_numba_type():
    variants = [(array, typeof(array)) for array in array_variants()]
    assert len({kind for _, kind in variants}) >= 25  # the variants cover dtypes, dimensions, layouts and flags
    for (first, first_type), (second, second_type) in itertools.combinations(variants, 2):
        if field_kinds((first,)) == field_kinds((second,)):
            assert first_type == second_type, (first_type, second_type)

