"""Package line counts and the largest functions of fibrelmp at one or more git revisions.

    python tools/code_size.py 10ddc4e HEAD [--top 15]

Reads the revisions from git (``git ls-tree`` / ``git show REV:path``), so the work tree is
not touched and any commit can be measured. Prints Markdown:

* per package folder of ``fibrelmp/`` (the files directly in it): files and lines of Python
  and of the C/C++ plugin sources, one column pair per revision, and the totals;
* per revision, the largest Python functions and methods (lines from ``def`` to the last line
  of the body, as ``ast`` gives them) and every module over 600 lines.
"""

from __future__ import annotations

import argparse
import ast
import subprocess
import sys
from collections import defaultdict
from pathlib import PurePosixPath

SOURCE_SUFFIXES = {".py": "python", ".cpp": "c++", ".h": "c++", ".c": "c++"}


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout


def sources(rev: str) -> dict[str, str]:
    """Path -> text of every Python and C/C++ source under fibrelmp/ at ``rev``."""
    paths = [p for p in _git("ls-tree", "-r", "--name-only", rev, "fibrelmp").splitlines()
             if PurePosixPath(p).suffix in SOURCE_SUFFIXES]
    return {p: _git("show", f"{rev}:{p}") for p in paths}


def package_counts(files: dict[str, str]) -> dict[str, dict[str, list[int]]]:
    """Folder -> language -> [files, lines]."""
    counts: dict[str, dict[str, list[int]]] = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for path, text in files.items():
        entry = counts[str(PurePosixPath(path).parent)][SOURCE_SUFFIXES[PurePosixPath(path).suffix]]
        entry[0] += 1
        entry[1] += len(text.splitlines())
    return counts


def functions(files: dict[str, str]) -> list[tuple[int, str]]:
    """(lines, 'path::Class.name') of every Python function and method."""
    found = []
    for path, text in files.items():
        if not path.endswith(".py"):
            continue
        tree = ast.parse(text)
        stack = [(tree, "")]
        while stack:
            node, prefix = stack.pop()
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    name = f"{prefix}{child.name}"
                    found.append((child.end_lineno - child.lineno + 1, f"{path}::{name}"))
                    stack.append((child, f"{name}."))
                elif isinstance(child, ast.ClassDef):
                    stack.append((child, f"{prefix}{child.name}."))
    return sorted(found, reverse=True)


def package_table(revs: list[str], counts: list[dict]) -> list[str]:
    head = " | ".join(f"{r} py files | {r} py lines | {r} C++ files | {r} C++ lines" for r in revs)
    lines = [f"| package folder | {head} |", "|---|" + "---:|" * (4 * len(revs))]
    totals = [[0, 0, 0, 0] for _ in revs]
    for folder in sorted(set().union(*counts)):
        cells = []
        for i, count in enumerate(counts):
            row = count.get(folder, {})
            values = [*row.get("python", [0, 0]), *row.get("c++", [0, 0])]
            totals[i] = [t + v for t, v in zip(totals[i], values)]
            cells.extend(str(v) if v else "-" for v in values)
        lines.append(f"| {folder} | {' | '.join(cells)} |")
    lines.append(f"| **total** | {' | '.join(str(v) for t in totals for v in t)} |")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("revs", nargs="+", help="git revisions, e.g. 10ddc4e HEAD")
    parser.add_argument("--top", type=int, default=15, help="how many of the largest functions")
    args = parser.parse_args(argv)
    per_rev = [sources(rev) for rev in args.revs]
    print("## Lines per package folder\n")
    print("\n".join(package_table(args.revs, [package_counts(f) for f in per_rev])))
    for rev, files in zip(args.revs, per_rev):
        print(f"\n## Largest functions at {rev}\n\n| lines | function |\n|---:|---|")
        for length, name in functions(files)[:args.top]:
            print(f"| {length} | `{name}` |")
        big = sorted((len(t.splitlines()), p) for p, t in files.items() if p.endswith(".py"))
        big = [f"`{p}` {n}" for n, p in reversed(big) if n > 600]
        print(f"\nModules over 600 lines at {rev}: {', '.join(big) or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
