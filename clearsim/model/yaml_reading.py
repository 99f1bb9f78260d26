"""YAML text → Python values for mechanism files and `--set` values: safe loaders that say where a value is unreadable.

`!!float abc` or `!!int 12x` is a located ConstructorError (a YAMLError), not a ValueError traceback; a value is at most
MAX_VALUE_CHARACTERS long (names, numbers, units and file paths are short; Python refuses to read an integer of more
than 4300 digits, and checking a value with a unit takes time growing with the square of its length).
"""

from __future__ import annotations

import yaml
from yaml.constructor import ConstructorError

from clearsim.model.messages import show

MAX_VALUE_CHARACTERS = 256
YAML_TAG_PREFIX = "tag:yaml.org,2002:"
# what a constructor raises on a value its tag cannot read: `!!float abc`, `!!int 12x`, `!!bool maybe`, `!!int ""`
CONSTRUCTION_FAILURES = (ValueError, TypeError, KeyError, IndexError, AttributeError, OverflowError)


class _ReadsValuesOrSaysWhere:
    """A loader mixin: a value its tag cannot read is a located ConstructorError, not a ValueError traceback."""

    def construct_object(self, node, deep=False):
        try:
            return super().construct_object(node, deep)
        except CONSTRUCTION_FAILURES:
            tag = node.tag.replace(YAML_TAG_PREFIX, "!!")
            raise ConstructorError(None, None, f"the tag {tag} cannot read {show(node.value)}",
                                   node.start_mark) from None


class CheckedLoader(_ReadsValuesOrSaysWhere, yaml.SafeLoader):
    """The pure-Python safe loader: no nesting limit of its own, the wording the syntax hints know."""


class FastCheckedLoader(_ReadsValuesOrSaysWhere, getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """libyaml's safe loader when PyYAML has it (~9× faster); libyaml 0.2.6 (PyYAML 6.0.4) refuses nesting deeper
    than 1000 levels while it scans ahead, libyaml 0.2.5 does not."""

