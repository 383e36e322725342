"""Write every command output shown in README.md and docs/*.md from a fresh run of that command.

A block in a page is

    <!-- output: pressplan check my-press.yaml -->
    ```text
    ... (written here)
    ```
    <!-- output:end -->

(indented as the list item it sits in), and a number in the text is

    <!-- value: pressplan bound cases/wang2023-side-panel.yaml --json | spm -->13.04<!-- /value -->

(the command's JSON output, a dotted path into it: keys, ``{a key with dots}``, list indices, or
``[key=value]`` for the item of a list whose ``key`` is ``value``, optionally ``/ 1000`` or ``* 100``; written
with the decimals shown). The blocks and values of all pages run in page order in one scratch folder that
holds a link to ``cases/``, so a later block may read a file an earlier one wrote (``pressplan new
my-press.yaml``, then ``pressplan check my-press.yaml``). What a block shows is the command's stdout and stderr,
without what depends on the machine or the moment: the solver's time and iteration count, the files written.
``tests/test_docs.py`` runs the same commands and compares (numbers to their last printed digit), so a number
changed by hand, or one a change of the code makes stale, fails.

    python scripts/docs_outputs.py          # rewrite every block
    python scripts/docs_outputs.py --check  # exit 1 naming the stale blocks
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import sys
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
BLOCK = re.compile(
    r"(?P<indent>[ \t]*)<!-- output: (?P<command>.+?) -->\n(?P=indent)```text\n(?P<body>.*?)(?P=indent)```\n"
    r"(?P=indent)<!-- output:end -->",
    re.S,
)
OUT_OPTION = ("solve", "laws", "compare", "cam", "line")  # commands that write a folder: sent to the scratch folder
DROPPED = re.compile(r"^\s+(wrote |solver: )")  # lines that depend on the run, not on the case
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


VALUE = re.compile(r"<!-- value: (?P<command>.+?) \| (?P<path>[^>]+?) -->(?P<shown>[^<]*)<!-- /value -->")


@dataclass(frozen=True)
class Value:
    page: Path
    command: str
    path: str
    shown: str
    span: tuple[int, int]


def values(pages: tuple[Path, ...] = PAGES) -> list[Value]:
    """Every inline value of ``pages``, in page order."""
    return [
        Value(page, m["command"], m["path"], m["shown"], m.span())
        for page in pages
        for m in VALUE.finditer(page.read_text(encoding="utf-8"))
    ]


def lookup(data, path: str):  # noqa: ANN001, ANN201 - JSON data
    """The item at dotted ``path`` in ``data``: keys (``{a key with . or [ in it}``), list indices,
    ``[key=value]`` list items."""
    for part in re.findall(r"\{[^}]*\}|\[[^\]]+\]|[^.\[\]{}]+", path):
        if part.startswith("{"):
            data = data[part[1:-1]]
        elif part.startswith("["):
            key, _, want = part[1:-1].partition("=")
            data = next(item for item in data if str(item.get(key)) == want)
        elif isinstance(data, list):
            data = data[int(part)]
        else:
            data = data[part]
    return data


def evaluate(data, expression: str) -> float:  # noqa: ANN001 - JSON data
    """``PATH``, ``PATH / NUMBER`` or ``PATH * NUMBER`` (a unit shown: N m as kN m)."""
    m = re.fullmatch(r"(.*?)(?:\s+([*/])\s+([0-9.eE+-]+))?", expression.strip())
    path, op, factor = m[1], m[2], m[3]
    value = float(lookup(data, path))
    return value / float(factor) if op == "/" else value * float(factor) if op == "*" else value


def shown_like(value: float, shown: str) -> str:
    """``value`` with as many decimals as ``shown`` has."""
    decimals = len(shown.split(".")[1]) if "." in shown else 0
    return f"{value:.{decimals}f}"


@dataclass(frozen=True)
class Block:
    page: Path
    command: str
    indent: str
    body: str  # as the page holds it, without the indent
    span: tuple[int, int]


def blocks(pages: tuple[Path, ...] = PAGES) -> list[Block]:
    """Every output block of ``pages``, in page order."""
    found = []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for m in BLOCK.finditer(text):
            body = "".join(line.removeprefix(m["indent"]) for line in m["body"].splitlines(keepends=True))
            found.append(Block(page, m["command"], m["indent"], body, m.span()))
    return found


@contextlib.contextmanager
def scratch() -> Iterator[Path]:
    """A scratch folder, the working folder meanwhile, with ``cases`` linked to the project's."""
    here = Path.cwd()
    with tempfile.TemporaryDirectory(prefix="pressplan-docs-") as folder:
        (Path(folder) / "cases").symlink_to(ROOT / "cases")
        os.chdir(folder)
        try:
            yield Path(folder)
        finally:
            os.chdir(here)


def run(command: str) -> str:
    """The shown output of ``command`` (``pressplan ...``), run in the working folder."""
    from planning.cli import main

    args = shlex.split(command)
    if args[0] != "pressplan":
        raise ValueError(f"not a pressplan command: {command}")
    args = args[1:]
    if args[0] in OUT_OPTION and "--out" not in args:
        args += ["--out", f"out/{len(os.listdir('.'))}"]
    if args[0] in ("solve", "line"):
        args.append("--no-plots")
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        main(args)
    lines = (out.getvalue() + err.getvalue()).splitlines()
    return "".join(f"{line}\n" for line in lines if not DROPPED.match(line))


def fresh_outputs(
    pages: tuple[Path, ...] = PAGES, keep: Callable[[str], bool] = lambda command: True
) -> list[tuple[Block, str]]:
    """Each block (whose command ``keep`` accepts) with its command's output now."""
    with scratch():
        return [(block, run(block.command)) for block in blocks(pages) if keep(block.command)]


def fresh_values(pages: tuple[Path, ...] = PAGES, commands: set[str] | None = None) -> list[tuple[Value, str]]:
    """Each inline value (of ``commands`` only, when given) as its command gives it now, written with the
    decimals shown (each command run once)."""
    import json

    outputs: dict[str, object] = {}
    found = []
    with scratch():
        for value in values(pages):
            if commands is not None and value.command not in commands:
                continue
            if value.command not in outputs:
                outputs[value.command] = json.loads(run(value.command))
            found.append((value, shown_like(evaluate(outputs[value.command], value.path), value.shown)))
    return found


def differences(shown: str, fresh: str) -> list[str]:
    """Where ``shown`` and ``fresh`` differ: words must be equal, numbers within one unit of the last
    digit ``shown`` prints (round-off across machines)."""
    problems = []
    a_lines, b_lines = shown.splitlines(), fresh.splitlines()
    if len(a_lines) != len(b_lines):
        return [f"{len(a_lines)} lines shown, {len(b_lines)} now"]
    for a, b in zip(a_lines, b_lines, strict=True):
        if NUMBER.sub("#", a) != NUMBER.sub("#", b):
            problems.append(f"shown {a.strip()!r}, now {b.strip()!r}")
            continue
        for x, y in zip(NUMBER.findall(a), NUMBER.findall(b), strict=True):
            unit = 10.0 ** -len(x.split(".")[1]) if "." in x else 1.0
            if abs(float(x) - float(y)) > unit * (1 + 1e-9):
                problems.append(f"shown {x}, now {y} in {a.strip()!r}")
    return problems


def _replacement(item: Block | Value, fresh: str) -> str:
    if isinstance(item, Value):
        return f"<!-- value: {item.command} | {item.path} -->{fresh}<!-- /value -->"
    body = "".join(f"{item.indent}{line}\n" if line else "\n" for line in fresh.splitlines())
    return (
        f"{item.indent}<!-- output: {item.command} -->\n{item.indent}```text\n{body}"
        f"{item.indent}```\n{item.indent}<!-- output:end -->"
    )


def write(results: list[tuple[Block | Value, str]]) -> None:
    """Put each fresh output into its block or value (pages rewritten from the last one up)."""
    for page in {item.page for item, _ in results}:
        text = page.read_text(encoding="utf-8")
        mine = sorted(((b, o) for b, o in results if b.page == page), key=lambda r: -r[0].span[0])
        for item, fresh in mine:
            text = text[: item.span[0]] + _replacement(item, fresh) + text[item.span[1] :]
        page.write_text(text, encoding="utf-8")


def stale(results: list[tuple[Block | Value, str]]) -> dict[str, list[str]]:
    """What differs between each shown block or value and its fresh one, by where it is."""
    found = {}
    for item, fresh in results:
        shown = item.body if isinstance(item, Block) else item.shown
        problems = differences(shown, fresh)
        if problems:
            where = item.command if isinstance(item, Block) else f"{item.command} | {item.path}"
            found[f"{item.page.name}: {where}"] = problems
    return found


def main(argv: list[str]) -> int:
    results = [*fresh_outputs(), *fresh_values()]
    if "--check" in argv:
        problems = stale(results)
        for where, what in problems.items():
            print(f"{where}: {what[0]}")
        return 1 if problems else 0
    write(results)
    print(f"wrote {len(results)} blocks and values in {len({b.page for b, _ in results})} pages")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
