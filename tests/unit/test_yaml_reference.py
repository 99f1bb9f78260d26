"""docs/yaml.md against the schema: its generated key tables are current and cover every field."""

import importlib.util
import re
import typing
from pathlib import Path

from pydantic import BaseModel

from clearsim.model.loader import load_mechanism_text
from clearsim.model.schema import Mechanism

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "yaml.md"
SCRIPT = ROOT / "docs" / "scripts" / "yaml_reference.py"


def _generator():
    spec = importlib.util.spec_from_file_location("yaml_reference", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _schema_models(model: type[BaseModel], found: dict | None = None) -> dict[str, type[BaseModel]]:
    """Every model reachable from `model` through its fields (walked here, not by the generator)."""
    found = {} if found is None else found
    found[model.__name__] = model
    pending = [info.annotation for info in model.model_fields.values()]
    while pending:
        annotation = pending.pop()
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            if annotation.__name__ not in found:
                _schema_models(annotation, found)
        else:
            pending += typing.get_args(annotation)
    return found


def _sections(text: str) -> dict[str, str]:
    """Anchor id → the text of its section in the generated region."""
    parts = re.split(r'<a id="([^"]+)"></a>', text)
    return dict(zip(parts[1::2], parts[2::2]))


def test_generated_tables_match_the_schema():
    generator = _generator()
    written = generator.generated_region(DOC.read_text(encoding="utf-8"))
    assert written == generator.reference_markdown(), (
        "docs/yaml.md is out of date with clearsim/model/schema.py: run python3 docs/scripts/yaml_reference.py")


def test_every_field_of_every_model_has_a_row():
    generator = _generator()
    sections = _sections(generator.generated_region(DOC.read_text(encoding="utf-8")))
    models = _schema_models(Mechanism)
    assert len(models) >= 21  # Mechanism and the 20 models below it when this test was written
    missing = []
    for name, model in models.items():
        section = sections.get(f"key-{name.lower()}", "")
        missing += [f"{name}.{field}" for field in model.model_fields if f"| `{field}` |" not in section]
    assert not missing, f"fields without a row in docs/yaml.md: {', '.join(missing)}"


def test_the_complete_example_is_the_bundled_file_and_valid():
    text = DOC.read_text(encoding="utf-8")
    match = re.search(r"<!-- example: (\S+) -->\n```yaml\n(.*?)```", text, re.S)
    assert match is not None, "docs/yaml.md lost its complete example"
    path, example = match.groups()
    assert example == (ROOT / path).read_text(encoding="utf-8"), f"the example differs from {path}"
    load_mechanism_text(example, name="docs/yaml.md example")  # raises InputError listing any problem
