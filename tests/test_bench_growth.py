"""benchmarks/growth.py --quick (small sizes; no timing assertions): both tables are printed, every
per-particle figure is positive, and the "largest / smallest" ratios and the worst growth ratio
agree with the ratios recomputed here from the printed table rows."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "growth.py"
COLUMNS = ["translate_s", "translate_B", "run_s", "run_B", "post_s", "post_B"]


@pytest.fixture(scope="module")
def output() -> str:
    done = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True,
                          text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return done.stdout


def table(out: str, family: str) -> list[list[float]]:
    block = out.split(family, 1)[1]
    rows = []
    for line in block.splitlines()[3:]:
        if not line.startswith("| "):
            break
        rows.append([float(c.replace(",", "")) for c in line.strip("| ").split(" | ")])
    return rows


@pytest.mark.parametrize("family, tag", [("FibreNet beads", "FibreNet"), ("MUSEN spheres", "MUSEN")])
def test_growth_table(output: str, family: str, tag: str) -> None:
    rows = table(output, family)
    assert len(rows) >= 2
    sizes = [r[0] for r in rows]
    assert sizes == sorted(sizes) and sizes[0] < sizes[-1]
    for r in rows:
        assert all(v > 0 for v in r[1:7]), r
    small, large = rows[0], rows[-1]
    expected = {c: large[i + 1] / small[i + 1] for i, c in enumerate(COLUMNS)}
    line = output.split(family, 1)[1].split("largest / smallest size:", 1)[1].splitlines()[0]
    printed = dict((k, float(v)) for k, v in re.findall(r"(\w+) ([0-9.]+)", line))
    for c in COLUMNS:
        # the table rounds to 2-3 digits; the ratio is computed from the unrounded figures
        assert printed[c] == pytest.approx(expected[c], rel=0.05, abs=0.02), c
    worst = float(re.search(rf"worst growth ratio \({tag}\): ([0-9.]+)", output).group(1))
    assert worst == pytest.approx(max(printed.values()), abs=0.006)
    assert "load average" in output


def test_worst_of_both_families(output: str) -> None:
    per_family = [float(x) for x in re.findall(r"worst growth ratio \((?:FibreNet|MUSEN)\): ([0-9.]+)", output)]
    overall = float(re.search(r"worst growth ratio \(all families run\): ([0-9.]+)", output).group(1))
    assert len(per_family) == 2 and overall == pytest.approx(max(per_family), abs=0.006)
