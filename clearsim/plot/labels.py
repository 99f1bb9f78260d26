"""Legend labels for overlaid runs, read from what differs between their stored configurations.

Two runs of the same file with `--set joints.J.clearance=0.1mm` in one get the labels
"J clearance 0.01 mm" and "J clearance 0.1 mm"; a run without clearance joints among runs
with some is "ideal". Values that differ the same way in several joints are merged
("A, J clearance 0.05 mm"). When nothing differs, or too much to fit a legend, the file
names are the labels.
"""

from __future__ import annotations

import yaml

from clearsim.plot.data import RunData

MAX_KEYS = 3
MAX_LENGTH = 48
MISSING = "–"
RADII = ("clearance", "journal_radius", "bearing_radius")


def flatten(node, prefix: tuple = ()) -> dict:
    """Nested YAML → {path tuple: value}; list items that have a `name` are keyed by it."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list) and node and all(isinstance(i, dict) and "name" in i for i in node):
        items = ((item["name"], {k: v for k, v in item.items() if k != "name"}) for item in node)
    else:
        return {prefix: node}
    flat = {}
    for key, value in items:
        flat.update(flatten(value, prefix + (str(key),)))
    return flat


def _text(value) -> str:
    if value is None:
        return MISSING
    if isinstance(value, list):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    return str(value)


def _differences(configs: list[dict]) -> dict:
    keys = dict.fromkeys(k for config in configs for k in config)
    differing = {}
    for key in keys:
        values = tuple(_text(config.get(key)) for config in configs)
        if len(set(values)) > 1:
            differing[key] = values
    return differing


def _merged(differing: dict) -> list[tuple[str, tuple]]:
    """Group keys of named items (joints.A.clearance, joints.J.clearance) that vary alike."""
    groups: dict[tuple, list[str]] = {}
    for key, values in differing.items():
        if len(key) >= 3:
            groups.setdefault((key[0], key[2:], values), []).append(key[1])
        else:
            groups.setdefault((None, key, values), [""])
    named = []
    for (collection, rest, values), items in groups.items():
        head = ", ".join(i for i in items if i)
        named.append((" ".join(p for p in (head, ".".join(rest)) if p), values))
    return named


def _config(run: RunData) -> dict:
    """The flattened stored YAML, with each revolute joint's radii replaced by its resolved clearance.

    `clearance: 0.25 mm` in one file and `journal_radius: 9.5 mm` in another both say "c", and
    that is what the legend should compare.
    """
    try:
        flat = flatten(yaml.safe_load(str(run.attrs.get("config_yaml", ""))) or {})
    except yaml.YAMLError:
        return {}
    joints = [key[1] for key in flat if len(key) == 3 and key[0] == "joints" and key[2] == "type"
              and flat[key] == "revolute"]
    for joint in joints:
        for radius in RADII:
            flat.pop(("joints", joint, radius), None)
        flat[("joints", joint, "clearance")] = f"{run.clearances.get(joint, 0.0) * 1e3:g} mm"
    return flat


def _file_labels(runs: list[RunData]) -> list[str]:
    stems = [run.path.stem for run in runs]
    if len(set(stems)) == len(stems):
        return stems
    return [f"{run.path.parent.name}/{run.path.stem}" for run in runs]


def run_labels(runs: list[RunData]) -> list[str]:
    """One legend label per run (see the module docstring)."""
    if len(runs) == 1:
        return [runs[0].path.stem]
    differing = _merged(_differences([_config(run) for run in runs]))
    ideal = [not run.clearance_joints for run in runs]
    if not differing or len(differing) > MAX_KEYS:
        return [("ideal" if flag and not all(ideal) else stem) for flag, stem in zip(ideal, _file_labels(runs))]
    labels = []
    for k, flag in enumerate(ideal):
        text = ", ".join(f"{name} {values[k]}" for name, values in differing)
        labels.append("ideal" if flag and not all(ideal) else text)
    if any(len(label) > MAX_LENGTH for label in labels) or len(set(labels)) < len(labels):
        return [("ideal" if flag and not all(ideal) else stem) for flag, stem in zip(ideal, _file_labels(runs))]
    return labels
