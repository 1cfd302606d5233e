"""docs/output.md is the schema's page (scripts/make_output_doc.py), README names every flag
bit, and no docstring cites a document that is not in the repository (SPEC.md lives outside
it)."""

import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_output_page_is_generated_from_the_schema():
    spec = importlib.util.spec_from_file_location(
        "make_output_doc", ROOT / "scripts" / "make_output_doc.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert (ROOT / "docs" / "output.md").read_text() == module.page(), (
        "docs/output.md is stale: run .venv/bin/python scripts/make_output_doc.py"
    )


def test_no_docstring_cites_the_spec_outside_the_repository():
    cited = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in (ROOT / "src").rglob("*.py")
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if re.search(r"\bSPEC(\.md)?\b", line)
    ]
    assert cited == []


def test_readme_names_every_flag_bit():
    # issue 22 item 9: README's flag list lacked attitude_undefined
    from speclight.schema import FLAG_MEANINGS

    listed = (ROOT / "README.md").read_text().split("a `flags` bit mask per epoch", 1)[1]
    listed = listed.split(")", 1)[0]
    assert [m for m in FLAG_MEANINGS.values() if f"`{m}`" not in listed] == []
