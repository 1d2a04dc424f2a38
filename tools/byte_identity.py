"""Byte-identity evidence: run every example and real-output case with one fibrelmp, compare two.

Two modes (stdlib only; the installation under test is used only through its ``fibrelmp``
executable, so two installations can be compared with the same input tree):

    python tools/byte_identity.py run OUT_ROOT [--fibrelmp PATH] [--tree REPO] [--only TEXT ...]
    python tools/byte_identity.py compare BEFORE/manifest.json AFTER/manifest.json

``run`` executes, serially, each into its own folder ``OUT_ROOT/<case>/``:

* every file under ``REPO/examples/`` that ``fibrelmp check`` accepts (``run`` into
  ``out/`` with ``--work work``, and ``translate -o job``);
* every real-output case under ``REPO/tests/data/real-outputs/``, run as its tests run it:
  each FibreNet case's ``input.txt`` in place (``-o out --work work``); each cmusen job script
  copied into the case folder beside the inputs it names (from its own folder, gunzipped from
  ``NAME.gz``, or from ``tests/data/real-inputs/musen/``), with an ``IMPORT_FROM_TEXT`` job
  first for the two agglomerate scripts that start from cmusen's imported ``agglo_init.mdem``
  (as ``tests/test_musen_real_outputs.py`` does), then ``run JOB -o out --work work``.
  None needs the real FibreNet or cmusen, so none is skipped.
  Short runs: a case in ``SHORTENED`` (one that takes longer than 3 minutes at full length)
  gets a smaller ``END_TIME`` in its copied job (listed in the manifest and the table).  Today
  it is empty: every case runs at its full length.

and writes ``OUT_ROOT/manifest.json``: per case the command, exit code and last error line,
and for every file the case wrote (the inputs the tool placed are left out) its relative path,
size, sha256 and, where something below had to be ignored, the sha256 of the compared text.

``compare`` prints a Markdown table: case -> files -> identical / differing (which files, and
for a text file its first differing compared line), plus files only one side wrote and exit
codes that differ; for a differing text file also how many lines a line diff finds only on either side
(files over 20,000 lines: how many differ position by position).

Ignored (cannot be identical by construction), in text files only:

* the inputs' checkout (``--tree``), written as ``<tree>`` (summary.json's ``input``: two
  runs may read the same inputs from two checkouts);
* the output root (``OUT_ROOT``), written as ``<root>`` (absolute paths in summary.json,
  data.fibrelmp.json, logs);
* the styles plugin's file name in ``plugin load`` lines (its name carries a hash of the C++
  sources, and the path is the installation's own);
* in ``log.lammps``: wall and CPU times (``Loop time of``, ``Performance:``, ``% CPU use``,
  ``CPU = ... seconds``, ``Total wall time``, the MPI timing breakdown table rows);
* in ``summary.json``: the keys ``wall_time`` and ``steps_per_second``.

Nothing else: every other byte, timestamps included, is compared.
"""

from __future__ import annotations

import argparse
import difflib
import gzip
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

TREE = Path(__file__).resolve().parent.parent
MUSEN_INPUTS = Path("tests/data/real-inputs/musen")

# Cases longer than 3 minutes at full length: the END_TIME their copied job script runs to.
# None: measured here, agglomerate_impact (3e-4 s) takes 203 s, the agglomerate 93 s, the drum
# 44 s; the one case just over 3 minutes is kept at full length, as the evidence is worth it.
SHORTENED: dict[str, str] = {}
# Scripts that start from cmusen's imported agglomerate: the import job the test adds first.
AGGLOMERATE_IMPORT = ("JOB\nSOURCE_FILE SphericalAgglomerate_text.txt\nRESULT_FILE agglo_init.mdem\n"
                      "COMPONENT IMPORT_FROM_TEXT\nJOB\n")
NEEDS_IMPORT = ("job_own_domain_test.txt", "job_recommended_step.txt")

IGNORED = ("the output root (written <root>) and the inputs' checkout (<tree>); the styles plugin's file in 'plugin load' lines; "
           "log.lammps wall/CPU times (Loop time, Performance, % CPU use, CPU = s, Total wall "
           "time, timing table rows); summary.json wall_time and steps_per_second")


@dataclass
class Case:
    """One command of the evidence run: its name (a folder under the output root) and what it runs."""

    name: str
    args: list[str]
    cwd: Path
    placed: set[str] = field(default_factory=set)  # inputs the tool put in the folder
    note: str = ""


# ---- the cases ---------------------------------------------------------------------------

def example_cases(fibrelmp: str, tree: Path, root: Path, only: list[str]) -> list[Case]:
    """``run`` and ``translate`` of every file under examples/ that ``fibrelmp check`` accepts."""
    cases = []
    for path in sorted(p for p in (tree / "examples").rglob("*") if p.is_file()):
        rel = path.relative_to(tree).as_posix()
        if only and not any(text in rel for text in only):
            continue
        probe = subprocess.run([fibrelmp, "-q", "check", str(path)], capture_output=True, text=True)
        if probe.returncode != 0 and "cannot tell the input format" in probe.stderr:
            continue
        folder = root / "run" / rel
        cases.append(Case(f"run/{rel}", ["-q", "run", str(path), "-o", str(folder / "out"),
                                         "--work", str(folder / "work")], folder))
        folder = root / "translate" / rel
        cases.append(Case(f"translate/{rel}", ["-q", "translate", str(path), "-o", str(folder / "job")],
                          folder))
    return cases


def fibrenet_cases(tree: Path, root: Path) -> list[Case]:
    """Each real FibreNet case's input.txt, run in place (it reads its model and restart files there)."""
    base = tree / "tests/data/real-outputs/fibrenet"
    cases = []
    for path in sorted(base.rglob("input.txt")):
        rel = path.relative_to(tree).as_posix()
        folder = root / "run" / rel
        cases.append(Case(f"run/{rel}", ["-q", "run", str(path), "-o", str(folder / "out"),
                                         "--work", str(folder / "work")], folder))
    return cases


def _place_job_inputs(script: Path, text: str, folder: Path, tree: Path) -> set[str]:
    """Copy (or gunzip) each SOURCE_FILE the job script names that is not made by an earlier job."""
    placed, made = set(), set()
    for key, value in re.findall(r"^(SOURCE_FILE|RESULT_FILE)\s+(\S+)", text, re.M):
        name = Path(value).name
        if key == "RESULT_FILE":
            made.add(name)
            continue
        if name in made or name in placed:
            continue
        for source in (script.parent / name, tree / MUSEN_INPUTS / name):
            if source.is_file():
                shutil.copyfile(source, folder / name)
                break
            if source.with_name(name + ".gz").is_file():
                with gzip.open(source.with_name(name + ".gz"), "rb") as src, open(folder / name, "wb") as dst:
                    shutil.copyfileobj(src, dst)
                break
        placed.add(name)
    return placed


def musen_cases(tree: Path, root: Path) -> list[Case]:
    """Each cmusen job script under real-outputs/musen, copied beside its inputs and run there."""
    cases = []
    for script in sorted((tree / "tests/data/real-outputs/musen").rglob("job_*.txt")):
        rel = script.relative_to(tree).as_posix()
        folder = root / "run" / rel
        folder.mkdir(parents=True, exist_ok=True)
        text = script.read_text()
        if script.name in NEEDS_IMPORT:
            text = AGGLOMERATE_IMPORT + text
        note = ""
        if rel in SHORTENED:
            text, count = re.subn(r"^END_TIME\s+\S+", f"END_TIME             {SHORTENED[rel]}", text, flags=re.M)
            assert count == 1, rel
            note = f"short run: END_TIME {SHORTENED[rel]}"
        (folder / script.name).write_text(text)
        placed = _place_job_inputs(script, text, folder, tree) | {script.name}
        cases.append(Case(f"run/{rel}", ["-q", "run", script.name, "-o", "out", "--work", "work"],
                          folder, placed, note))
    return cases


# ---- hashing, with what cannot be identical masked ---------------------------------------

_LOG_TIMES = re.compile(r"^(Loop time of|Performance:|Total wall time|.*% CPU use|.*CPU = .* seconds"
                        r"|Section \||\S+\s+\|\s*[-\d.e+]+\s+\|)")
_PLUGIN = re.compile(r"^(plugin\s+load\s+)\S+", re.M)


def _is_text(data: bytes) -> bool:
    if b"\0" in data[:65536]:
        return False
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def compared_text(path: Path, data: bytes, root: Path, tree: Path | None = None) -> str | None:
    """The text that is compared (IGNORED masked), or None for a binary file."""
    if not _is_text(data):
        return None
    text = data.decode("utf-8").replace(str(root), "<root>")
    if tree is not None:                # the inputs' checkout (summary.json's "input")
        text = text.replace(str(tree), "<tree>")
    text = _PLUGIN.sub(r"\1<fibrelmp styles plugin>", text)
    if path.name.startswith("log.lammps"):
        text = "\n".join("<time line>" if _LOG_TIMES.match(line) else line for line in text.split("\n"))
    if path.name == "summary.json":
        try:
            doc = json.loads(text)
        except ValueError:
            return text
        for key in ("wall_time", "steps_per_second"):
            if key in doc:
                doc[key] = "<ignored>"
        text = json.dumps(doc, indent=1)
    return text


def file_entry(path: Path, root: Path, tree: Path | None = None) -> dict:
    """Size, sha256 and (when masking changed it) the sha256 of the compared text."""
    data = path.read_bytes()
    entry = {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    text = compared_text(path, data, root, tree)
    if text is not None and text.encode("utf-8") != data:
        entry["compared_sha256"] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return entry


# ---- run mode ----------------------------------------------------------------------------

def run_case(fibrelmp: str, case: Case, root: Path, tree: Path | None = None) -> dict:
    """Run one case and describe what it wrote."""
    case.cwd.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    done = subprocess.run([fibrelmp, *case.args], cwd=case.cwd, capture_output=True, text=True,
                          env=dict(os.environ, OMP_NUM_THREADS="1"))
    files = {}
    for path in sorted(p for p in case.cwd.rglob("*") if p.is_file() and not p.is_symlink()):
        rel = path.relative_to(case.cwd).as_posix()
        if rel not in case.placed:
            files[rel] = file_entry(path, root, tree)
    errors = [line for line in done.stderr.splitlines() if line.startswith("error")]
    return {"command": ["fibrelmp", *case.args], "cwd": str(case.cwd), "exit": done.returncode,
            "error": errors[-1] if errors else "", "seconds": round(time.monotonic() - started, 1),
            "note": case.note, "files": files}


def run_mode(args: argparse.Namespace) -> int:
    fibrelmp = args.fibrelmp or shutil.which("fibrelmp")
    if not fibrelmp:
        sys.exit("no fibrelmp on PATH: give --fibrelmp PATH")
    root, tree = Path(args.root).resolve(), Path(args.tree).resolve()
    if root.exists() and any(root.iterdir()):
        sys.exit(f"{root} is not empty: choose a new output root")
    root.mkdir(parents=True, exist_ok=True)
    version = subprocess.run([fibrelmp, "--version"], capture_output=True, text=True).stdout.strip()
    cases = example_cases(fibrelmp, tree, root, args.only or []) + fibrenet_cases(tree, root) + musen_cases(tree, root)
    manifest = {"fibrelmp": fibrelmp, "version": version, "tree": str(tree), "root": str(root),
                "ignored": IGNORED, "cases": {}}
    for case in cases:
        if args.only and not any(text in case.name for text in args.only):
            continue
        print(f"{case.name} ...", end=" ", flush=True, file=sys.stderr)
        manifest["cases"][case.name] = result = run_case(fibrelmp, case, root, tree)
        print(f"exit {result['exit']}, {len(result['files'])} files, {result['seconds']} s",
              file=sys.stderr)
        (root / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
    print(root / "manifest.json")
    return 0


# ---- compare mode ------------------------------------------------------------------------

def _first_difference(a: Path, b: Path, root_a: Path, root_b: Path) -> str:
    """'line N: <a> | <b>' for two text files (as compared), or why it cannot be said."""
    if not (a.is_file() and b.is_file()):
        return "files no longer on disk"
    text_a = compared_text(a, a.read_bytes(), root_a)
    text_b = compared_text(b, b.read_bytes(), root_b)
    if text_a is None or text_b is None:
        return "binary"
    lines_a, lines_b = text_a.split("\n"), text_b.split("\n")
    unequal = [n for n, (x, y) in enumerate(zip(lines_a, lines_b), 1) if x != y]
    if not unequal:
        return f"line {min(len(lines_a), len(lines_b)) + 1}: one file ends ({len(lines_a)} vs {len(lines_b)} lines)"
    first = unequal[0]
    if max(len(lines_a), len(lines_b)) <= 20000:       # a line diff (quadratic at worst)
        ops = difflib.SequenceMatcher(None, lines_a, lines_b, autojunk=False).get_opcodes()
        removed = sum(i2 - i1 for tag, i1, i2, _, _ in ops if tag in ("replace", "delete"))
        added = sum(j2 - j1 for tag, _, _, j1, j2 in ops if tag in ("replace", "insert"))
        counts = f"diff: {removed} lines only before, {added} only after"
    else:
        counts = f"{len(unequal)} of {max(len(lines_a), len(lines_b))} lines differ by position"
    return f"line {first}: `{lines_a[first - 1][:70]}` vs `{lines_b[first - 1][:70]}`; {counts}"


def _key(entry: dict) -> str:
    return entry.get("compared_sha256", entry["sha256"])


def compare_case(name: str, a: dict | None, b: dict | None, roots: tuple[Path, Path]) -> str:
    """One table row for a case."""
    if a is None or b is None:
        return f"| {name} | - | only in {'after' if a is None else 'before'} |"
    note = f" ({a['note'] or b['note']})" if a["note"] or b["note"] else ""
    if a["exit"] != b["exit"]:
        return (f"| {name}{note} | {len(a['files'])} / {len(b['files'])} | exit {a['exit']} vs "
                f"{b['exit']}: {(a['error'] or b['error'])[:120]} |")
    same, differing = [], []
    for rel in sorted(set(a["files"]) | set(b["files"])):
        fa, fb = a["files"].get(rel), b["files"].get(rel)
        if fa is None or fb is None:
            differing.append(f"{rel}: only {'after' if fa is None else 'before'}")
        elif _key(fa) == _key(fb):
            same.append(rel)
        else:
            where = _first_difference(Path(a["cwd"]) / rel, Path(b["cwd"]) / rel, *roots)
            differing.append(f"{rel} ({where})")
    verdict = "identical" if not differing else "differing: " + "; ".join(differing)
    return f"| {name}{note} | {len(same) + len(differing)} (exit {a['exit']}) | {verdict} |"


def compare_mode(args: argparse.Namespace) -> int:
    before = json.loads(Path(args.before).read_text())
    after = json.loads(Path(args.after).read_text())
    roots = (Path(before["root"]), Path(after["root"]))
    names = list(dict.fromkeys([*before["cases"], *after["cases"]]))
    rows = [compare_case(n, before["cases"].get(n), after["cases"].get(n), roots) for n in names]
    identical = sum(r.endswith("| identical |") for r in rows)
    print(f"Before: {before['fibrelmp']} ({before['version'].splitlines()[0] if before['version'] else '?'})  ")
    print(f"After: {after['fibrelmp']} ({after['version'].splitlines()[0] if after['version'] else '?'})  ")
    print(f"Inputs: {before['tree']} / {after['tree']}\n")
    print("| case | files | result |\n|---|---|---|")
    print("\n".join(rows))
    print(f"\n{identical} of {len(rows)} cases identical. Ignored: {IGNORED}.")
    return 0 if identical == len(rows) else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="mode", required=True)
    run = sub.add_parser("run", help="run every case into ROOT and write ROOT/manifest.json")
    run.add_argument("root")
    run.add_argument("--fibrelmp", help="the fibrelmp executable (default: the one on PATH)")
    run.add_argument("--tree", default=str(TREE), help="the repository whose examples/ and tests/data are run")
    run.add_argument("--only", action="append", help="only cases whose name contains this text (repeatable)")
    compare = sub.add_parser("compare", help="compare two manifests (Markdown table on stdout)")
    compare.add_argument("before")
    compare.add_argument("after")
    args = parser.parse_args(argv)
    return run_mode(args) if args.mode == "run" else compare_mode(args)


if __name__ == "__main__":
    sys.exit(main())
