"""Every ```python block of README and the book runs as it stands: each page's blocks in order, in
a folder holding the files of docs/examples."""

import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs" / "src").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def pages_with_python():
    return [p for p in PAGES if BLOCK.search(p.read_text())]


def test_the_python_chapter_and_readme_have_examples():
    names = {p.name for p in pages_with_python()}
    assert {"README.md", "python.md"} <= names, names


@pytest.mark.parametrize("page", pages_with_python(), ids=lambda p: p.name)
def test_every_python_example_runs(page, tmp_path, monkeypatch):
    for f in (ROOT / "docs" / "examples").iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / f.name)
    monkeypatch.chdir(tmp_path)
    for k, code in enumerate(BLOCK.findall(page.read_text())):
        try:
            exec(compile(code, f"{page.name}, python block {k + 1}", "exec"), {"__name__": "doc"})
        except Exception as e:
            raise AssertionError(f"{page.name}, python block {k + 1}:\n{code}") from e
