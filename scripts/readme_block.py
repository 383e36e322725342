"""Replace a generated block of README.md or a page of docs/: the text between ``<!-- NAME:begin -->`` and
``<!-- NAME:end -->``, in whichever page holds it."""

from __future__ import annotations

from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def page_with(name: str) -> Path:
    """The page (README.md or docs/*.md) that holds block ``name``."""
    for page in (README, *sorted((README.parent / "docs").glob("*.md"))):
        if f"<!-- {name}:begin -->" in page.read_text(encoding="utf-8"):
            return page
    raise KeyError(f"no page holds the block {name!r}")


def replace_block(name: str, text: str, readme: Path | None = None) -> None:
    """Put ``text`` (ending in a newline) between the markers of block ``name`` (in ``readme``, else the
    page that holds it)."""
    readme = readme if readme is not None else page_with(name)
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    content = readme.read_text(encoding="utf-8")
    head, rest = content.split(begin)
    _, tail = rest.split(end)
    readme.write_text(f"{head}{begin}\n{text}{end}{tail}", encoding="utf-8")
