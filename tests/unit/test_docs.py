"""The documentation: every relative link and image resolves, and docs/ reads as the product as it is now."""

import re
import unicodedata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
LINKED_PAGES = [ROOT / "README.md", *PAGES]

# Development history and references outside the repository, which the docs must not contain.
HISTORY_WORDING = re.compile(r"\bsession[- ]\d|\bissue #|\bissue \d|\bhelper\b|DESIGN\.md|\.\./shared", re.IGNORECASE)

FENCED_CODE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r"`[^`\n]*`")
# [text](target) or ![alt](target); a bracket right after a word character is an index (L[y](t)), not a link.
LINK = re.compile(r"(?<![\w\]])!?\[[^\]\n]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_REFERENCE = re.compile(r"<(?:img|a)\s[^>]*?(?:src|href)=\"([^\"]+)\"", re.IGNORECASE)
HTML_ANCHOR = re.compile(r"<a\s[^>]*?(?:id|name)=\"([^\"]+)\"", re.IGNORECASE)
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)


def _prose(text: str) -> str:
    """The page without its code: fenced blocks and inline code spans."""
    return INLINE_CODE.sub("", FENCED_CODE.sub("", text))


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    kept = "".join(
        character
        for character in heading.lower()
        if character in " -_" or unicodedata.category(character)[0] in "LN"
    )
    return kept.replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    text = FENCED_CODE.sub("", page.read_text(encoding="utf-8"))
    anchors, seen = set(), {}
    for heading in HEADING.findall(text):
        slug = _slug(heading)
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        anchors.add(slug if count == 0 else f"{slug}-{count}")
    return anchors | set(HTML_ANCHOR.findall(text))


def _relative_targets(page: Path) -> list[str]:
    prose = _prose(page.read_text(encoding="utf-8"))
    targets = LINK.findall(prose) + HTML_REFERENCE.findall(prose)
    return [target for target in targets if not re.match(r"[a-z][a-z0-9+.-]*:", target, re.IGNORECASE)]


def broken_links(page: Path) -> list[str]:
    """Each relative link or image of the page whose file, or whose anchor in a Markdown page, is missing."""
    broken = []
    for target in _relative_targets(page):
        path_part, _, fragment = target.partition("#")
        linked = (page.parent / path_part).resolve() if path_part else page
        if not linked.exists():
            broken.append(f"{target}: no file {linked.relative_to(ROOT) if linked.is_relative_to(ROOT) else linked}")
        elif fragment and linked.suffix == ".md" and fragment not in _anchors(linked):
            broken.append(f"{target}: no heading or anchor '#{fragment}' in {linked.name}")
    return broken


def history_lines(page: Path) -> list[str]:
    """Each line of the page that speaks of development history or of a file outside the repository."""
    lines = page.read_text(encoding="utf-8").splitlines()
    return [f"{page.name}:{number}: {line.strip()}" for number, line in enumerate(lines, 1) if HISTORY_WORDING.search(line)]


@pytest.mark.parametrize("page", LINKED_PAGES, ids=lambda page: page.name)
def test_every_relative_link_and_image_resolves(page):
    assert broken_links(page) == []


@pytest.mark.parametrize("page", LINKED_PAGES, ids=lambda page: page.name)
def test_page_reads_as_the_product_now(page):
    assert history_lines(page) == []


def test_the_checks_find_what_they_look_for(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(
        "# Title\n\n## Compile time\n\nSee [it](#compile-time), [gone](#nowhere), [file](missing.md), "
        "![figure](figures/none.png), `[code](ignored.md)` and L[y](t).\n\nMeasured in Session 8, issue #6, "
        "DESIGN.md §4, ../shared/reference.\nThe session-2 figure, with the helper.\n",
        encoding="utf-8",
    )
    assert [entry.split(":")[0] for entry in broken_links(page)] == ["#nowhere", "missing.md", "figures/none.png"]
    assert len(history_lines(page)) == 2
    assert _slug("Sticking: `stick: exact` (default) or `smooth`") == "sticking-stick-exact-default-or-smooth"
    assert _slug("13. Key reference") == "13-key-reference"


WEAR_EXAMPLE = re.compile(r"^    (wear: \{.*?\}\})\s*$", re.MULTILINE | re.DOTALL)


def test_the_wear_block_of_the_contact_page_is_accepted_on_a_clearance_joint():
    """The `wear:` example of model-contact.md, as printed, on the bundled breaker's joint A: a valid profile (depth ≥ 0
    everywhere) and Archard block, not an input error, and no pocket tighter than the journal (no warning)."""
    import yaml

    from clearsim.model.loader import load_mechanism_text
    from clearsim.model.plausibility import plausibility_warnings

    example = yaml.safe_load(WEAR_EXAMPLE.search((DOCS / "model-contact.md").read_text(encoding="utf-8")).group(1))
    document = yaml.safe_load((ROOT / "clearsim" / "configs" / "uhv_breaker.yaml").read_text(encoding="utf-8"))
    joint = next(j for j in document["joints"] if j["name"] == "A")
    joint["wear"] = example["wear"]
    mechanism = load_mechanism_text(yaml.safe_dump(document)).mechanism
    assert next(j for j in mechanism.joints if j.name == "A").wear.profile is not None
    assert not [w for w in plausibility_warnings(mechanism) if "wear" in w.path]
