"""No user text (file names, type / material / geometry names) can inject LAMMPS commands.

A newline in an input file's name used to end the comment it is printed in, so ``lmp -in``
ran the next line (``shell touch PWNED``); a U+2028 did the same in ``fibrelmp run`` only
(the runner split lines with str.splitlines()); a type named ``B\"\"\"`` opened a LAMMPS
multi-line string in a comment, so ``lmp -in`` replayed nothing and exited 0.  Every case
here must either run with the name made harmless or be refused with exit code 2; nothing
may create PWNED, and ``lmp -in`` must replay exactly what ``fibrelmp run`` computed.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp.errors import InputError, RunError
from fibrelmp.lammps_text import (UnsafeText, comment_text, input_lines, lammps_word,
                                  template_environment)

from .conftest import REPO

BIN = Path(sys.executable).parent
LMP = BIN / "lmp"
CLI = [sys.executable, "-m", "fibrelmp.cli", "-q"]
needs_lmp = pytest.mark.skipif(not LMP.exists(), reason=f"no lmp executable next to {sys.executable}")

# every character LAMMPS or Python may take for a line end, and what LAMMPS gives a meaning
HOSTILE = ("x\n shell touch PWNED\r\n shell touch PWNED\r\v\f\x1c\x1d\x1e\x1f\x85\u2028shell touch "
           "PWNED\u2029 \"'\"\"\"$x${y}$(z)#&\\\x00\udcff\u201c\u201c\u201c\u00a0&")
LINE_BREAKS = "\n\r\v\f\x1c\x1d\x1e\x1f\x85\u2028\u2029"


def _cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, OMP_NUM_THREADS="1"))


def _lmp(job: Path) -> subprocess.CompletedProcess:
    from fibrelmp._lammps import lmp_executable_env

    return subprocess.run([str(LMP), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=job, env=lmp_executable_env(), capture_output=True, timeout=300)


def _pwned(root: Path) -> list[Path]:
    return [p for p in root.rglob("*") if p.name.startswith("PWNED")]


def _assert_ok_or_refused(proc: subprocess.CompletedProcess, what: str) -> bool:
    """True when the command succeeded; exit 2 (InputError) is the only other answer."""
    assert proc.returncode in (0, 2), f"{what}: exit {proc.returncode}\n{proc.stdout}\n{proc.stderr}"
    if proc.returncode == 2:
        assert re.search(r":\d+: |: ", proc.stderr), proc.stderr
    return proc.returncode == 0


def _assert_safe_job(job: Path) -> None:
    """in.lammps and the data file: printable ASCII lines LAMMPS reads one by one; user text
    only after a '#' (or in the data-file title)."""
    script = (job / "in.lammps").read_bytes().decode("ascii")
    input_lines(script, job / "in.lammps")          # no line LAMMPS would join
    for line in script.split("\n"):
        assert re.fullmatch(r"[\x20-\x7e]*", line), line
        # the one '$' fibrelmp itself writes: the FibreNet kick's "reset_timestep $(step+1)"
        assert '"""' not in line and "$" not in line.replace("$(step+1)", ""), line
        if "PWNED" in line or "shell" in line:
            assert line.startswith("#"), line
    data = (job / "data.lammps").read_bytes().decode("ascii").split("\n")
    for k, line in enumerate(data):
        assert re.fullmatch(r"[\x20-\x7e]*", line), line
        if k > 0 and "PWNED" in line:
            assert "#" in line and "PWNED" not in line.partition("#")[0], line


# ----------------------------------------------------------------------------------------
# FibreNet
def _fibrenet_case(folder: Path, input_name: str, type_name: str = "F1") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    src = REPO / "examples" / "fibre_network"
    text = (src / "input.txt").read_text()
    text = text.replace("run\t2000", "run\t200").replace("output_freq\t400", "output_freq\t100")
    text = re.sub(r"\bF1\b", lambda m: type_name, text)
    model = re.sub(r"\bF1\b", lambda m: type_name, (src / "model.txt").read_text())
    (folder / input_name).write_text(text)
    (folder / "model.txt").write_text(model)
    return folder / input_name


@needs_lmp
@pytest.mark.parametrize("input_name", ["fn\n shell touch PWNED\n.txt", "fn\u2028shell touch PWNED.txt"],
                         ids=["newline", "u2028"])
def test_fibrenet_input_file_name_cannot_inject(tmp_path, input_name):
    inp = _fibrenet_case(tmp_path, input_name)
    translated = _cli(["translate", inp.name, "-o", "job"], tmp_path)
    replay = _lmp(tmp_path / "job") if translated.returncode == 0 else None
    ran = _cli(["run", inp.name, "-o", "out", "--work", "work"], tmp_path)
    assert not _pwned(tmp_path), "a LAMMPS shell command ran"
    _assert_ok_or_refused(ran, "run")
    if _assert_ok_or_refused(translated, "translate"):
        assert replay.returncode == 0, replay.stdout + replay.stderr
        assert (tmp_path / "job" / "frames.dump").stat().st_size > 0
        _assert_safe_job(tmp_path / "job")


@needs_lmp
def test_fibrenet_triple_quote_type_name_replays_like_run(tmp_path):
    inp = _fibrenet_case(tmp_path, "input.txt", type_name='B"""')
    translated = _cli(["translate", inp.name, "-o", "job"], tmp_path)
    if not _assert_ok_or_refused(translated, "translate"):
        assert re.search(r"input\.txt:\d+: ", translated.stderr), translated.stderr
        return
    replay = _lmp(tmp_path / "job")
    assert replay.returncode == 0, replay.stdout + replay.stderr
    ran = _cli(["run", inp.name, "-o", "out", "--work", "work"], tmp_path)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    a = (tmp_path / "work" / "frames.dump").read_bytes()
    assert a.count(b"ITEM: TIMESTEP") == 3          # steps 0, 100, 200
    assert (tmp_path / "job" / "frames.dump").exists(), "lmp -in replayed nothing"
    assert (tmp_path / "job" / "frames.dump").read_bytes() == a, "lmp -in replay differs from fibrelmp run"
    _assert_safe_job(tmp_path / "job")
    # the user's name is kept where it is data, not script: the FibreNet outputs
    assert any('B"""' in p.read_text() for p in (tmp_path / "out").iterdir() if p.suffix == ".xyz")


# ----------------------------------------------------------------------------------------
# MUSEN
HOSTILE_MATERIAL = 'Gl"""a$(s)#s&'
HOSTILE_GEOMETRY = 'Pl"""ate&'


def _musen_scene(folder: Path, scene_name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    text = (REPO / "examples" / "musen" / "SingelParticle_text.txt").read_text()
    text = text.replace(" Glass ", f" {HOSTILE_MATERIAL} ").replace("25 Plate ", f"25 {HOSTILE_GEOMETRY} ")
    (folder / scene_name).write_text(text)
    return folder / scene_name


@needs_lmp
def test_musen_script_scene_and_material_names_replay_like_run(tmp_path):
    """A cmusen script names a scene whose file, material and geometry names are hostile."""
    scene = _musen_scene(tmp_path, "sc\"\"\"$(x)&\u2028shell touch PWNED&.txt")
    script = (REPO / "examples" / "musen" / "single_particle_job.txt").read_text()
    script = (script.replace("SingelParticle_text.txt", scene.name)
              .replace("END_TIME             0.02", "END_TIME             2e-4")
              .replace("SIMULATION_STEP      1e-7", "SIMULATION_STEP      1e-6"))
    (tmp_path / "job.txt").write_text(script)
    translated = _cli(["translate", "job.txt", "-o", "job"], tmp_path)
    replay = _lmp(tmp_path / "job") if translated.returncode == 0 else None
    ran = _cli(["run", "job.txt", "--work", "work"], tmp_path)
    assert not _pwned(tmp_path), "a LAMMPS shell command ran"
    if _assert_ok_or_refused(translated, "translate"):
        assert replay.returncode == 0, replay.stdout + replay.stderr
        assert ran.returncode == 0, ran.stdout + ran.stderr
        a = (tmp_path / "work" / "job2" / "frames.dump").read_bytes()
        assert a.count(b"ITEM: TIMESTEP") == 4          # t = 0, 1e-4, 2e-4 and cmusen's last, 2.01e-4
        assert (tmp_path / "job" / "frames.dump").exists(), "lmp -in replayed nothing"
        assert (tmp_path / "job" / "frames.dump").read_bytes() == a, "lmp -in replay differs from run"
        _assert_safe_job(tmp_path / "job")
        text = (tmp_path / "job" / "in.lammps").read_text()
        assert "Gl```a_(s)_s_" in text and "Pl```ate_" in text      # names kept readable


@needs_lmp
def test_musen_scene_file_name_with_newline_cannot_inject(tmp_path):
    scene = _musen_scene(tmp_path, "sc\n shell touch PWNED\n.txt")
    translated = _cli(["translate", scene.name, "-o", "job"], tmp_path)
    ran = _cli(["run", scene.name, "--end-time", "2e-4", "--step", "1e-6", "--save-step", "1e-4",
                "-o", "result.txt", "--work", "work"], tmp_path)
    assert not _pwned(tmp_path), "a LAMMPS shell command ran"
    if _assert_ok_or_refused(translated, "translate"):
        _assert_safe_job(tmp_path / "job")     # (a replay would run MUSEN's default 1 s)
    if _assert_ok_or_refused(ran, "run"):
        _assert_safe_job(tmp_path / "work")
        assert (tmp_path / "result.txt").exists()


# ----------------------------------------------------------------------------------------
# DEMDF
@needs_lmp
@pytest.mark.parametrize("file_name", ["dm\n shell touch PWNED\n.json",
                                       "dm\"\"\"$(x)&\u2028shell touch PWNED&.json"],
                         ids=["newline", "quotes-u2028"])
def test_demdf_file_and_type_names_replay_like_run(tmp_path, file_name):
    doc = json.loads((REPO / "examples" / "demdf" / "drop_on_wall.json").read_text())
    hostile = HOSTILE.replace("\udcff", "")   # (a lone surrogate is no text the output JSON can hold)
    doc["name"] = hostile
    doc["timeEnd"] = 0.5
    for wall in doc["objects"]["walls"]:     # a shared wall type named by the user
        del wall["objectType"]
        wall["typename"] = hostile
    (tmp_path / file_name).write_text(json.dumps(doc))
    translated = _cli(["translate", file_name, "-o", "job"], tmp_path)
    replay = _lmp(tmp_path / "job") if translated.returncode == 0 else None
    ran = _cli(["run", file_name, "-o", "out", "--work", "work"], tmp_path)
    assert not _pwned(tmp_path), "a LAMMPS shell command ran"
    if _assert_ok_or_refused(translated, "translate"):
        assert replay.returncode == 0, replay.stdout + replay.stderr
        assert ran.returncode == 0, ran.stdout + ran.stderr
        a = (tmp_path / "work" / "frames.dump").read_bytes()
        assert a.count(b"ITEM: TIMESTEP") == 3          # t = 0, 0.25, 0.5
        assert (tmp_path / "job" / "frames.dump").exists(), "lmp -in replayed nothing"
        assert (tmp_path / "job" / "frames.dump").read_bytes() == a, "lmp -in replay differs from run"
        _assert_safe_job(tmp_path / "job")


# ----------------------------------------------------------------------------------------
# the escaping functions and the template environments
def test_comment_text_keeps_text_on_its_line_and_meaningless():
    out = comment_text(HOSTILE)
    assert isinstance(out, str) and len(out) == len(HOSTILE)
    assert re.fullmatch(r"[A-Za-z0-9 !%()*+,\-./:;<=>?@\[\]^_`{|}~]*", out), out
    assert not any(ch in out for ch in LINE_BREAKS + "\"'#$&\\\0")
    assert comment_text(out) == out
    assert comment_text("F1 m=1 R=0.42 (steel) [a-b]") == "F1 m=1 R=0.42 (steel) [a-b]"
    assert comment_text('B"""') == "B```"


def test_lammps_word_accepts_ids_and_refuses_the_rest():
    assert lammps_word("F1") == "F1" and lammps_word("_wall_2") == "_wall_2"
    for bad in ('B"""', "1a", "a b", "", "a#b", "a$b", "a&", "x\u2028", "é", "a-b"):
        with pytest.raises(InputError) as err:
            lammps_word(bad, "model.txt", 7, "type name")
        assert str(err.value).startswith("model.txt:7: type name ")


@pytest.mark.parametrize("bad", [HOSTILE, "a\nb", "a\u2028b", 'B"""', 'x"', "a&", "$x", "a#b", "it's",
                                 "\u201cq\u201d", "\x00"])
def test_template_environment_refuses_unescaped_user_text(bad):
    env = template_environment()
    with pytest.raises(UnsafeText):
        env.from_string("# from {{ name }}\nrun 1\n").render(name=bad)
    with pytest.raises(UnsafeText):
        env.from_string("{% for n in names %}{{ n }} {% endfor %}").render(names=["F1", bad])
    out = env.from_string("# from {{ name|comment }}\nrun 1\n").render(name=bad)
    assert out.split("\n")[1:] == ["run 1", ""]
    assert input_lines(out) == [out.split("\n")[0], "run 1"]


def test_template_environment_prints_numbers_and_safe_fragments():
    import numpy as np

    env = template_environment()
    out = env.from_string('{{ a }} {{ b }} {{ c }} {{ d }}').render(
        a=np.float64(0.5), b=np.int64(3), c='pair_coeff 1 1 lepton "0.5*r^2" 1.0', d=2.5)
    assert out == 'pair_coeff 1 1 lepton "0.5*r^2" 1.0'.join(["0.5 3 ", " 2.5"])


def _hostile_fibrenet_model(tmp_path):
    from fibrelmp.translate.fibrenet.reader import read as read_fibrenet

    inp = _fibrenet_case(tmp_path / "in", "input.txt")
    model = read_fibrenet(inp)
    model.source = tmp_path / HOSTILE
    model.particles.type_names = [HOSTILE + str(k) for k in range(len(model.particles.type_names))]
    return model


def test_rendered_fibrenet_job_with_hostile_names_is_safe(tmp_path):
    from fibrelmp.translate.lammps_job import write_job

    job = write_job(_hostile_fibrenet_model(tmp_path), tmp_path / "job")
    _assert_safe_job(job.folder)
    assert job.script.read_text() == job.text
    assert sum("PWNED" in line for line in job.text.split("\n")) == 2    # header + type list


def test_rendered_granular_job_with_hostile_names_is_safe(tmp_path, monkeypatch):
    """MUSEN scene with every name hostile; the plate is forced onto wall particles so the
    wall-particle type names are rendered too."""
    from fibrelmp.translate import granular_job
    from fibrelmp.translate.granular import walls
    from fibrelmp.translate.musen import scene as musen
    from fibrelmp.translate.musen.input import bare_scene_settings

    scene = _musen_scene(tmp_path, "scene.txt")
    model = musen.read(scene)
    bare_scene_settings(model, 2e-4, 1e-6, 1e-4)
    model.source = tmp_path / HOSTILE
    for k, m in enumerate(model.materials):
        m.name = f"{HOSTILE}{k}"
    for g in model.geometries:
        g.name = HOSTILE
    from fibrelmp import lammps_styles

    for kind in ("mesh", "box", "tiles"):
        if kind == "mesh" and not lammps_styles.plugin().available:
            continue
        if kind == "tiles":
            monkeypatch.setattr(walls, "detect_oriented_box", lambda v: None)
            monkeypatch.setattr(walls, "detect_cylinder", lambda v: None)
        with lammps_styles.stock(kind != "mesh"):    # fix musen/wall/mesh, or stock walls
            job = granular_job.write_granular_job(model, tmp_path / kind)
        assert [wp.kind for wp in job.wall_plans] == [kind]
        _assert_safe_job(job.folder)
        text = job.script.read_text()
        assert "# Wall-particle types:" in text or kind != "tiles"
        assert "# wall '" in text
        if kind == "mesh":       # the fix's triangle file: printable ASCII, no user text but labels
            mesh = (job.folder / "walls.mesh").read_bytes().decode("ascii")
            assert all(re.fullmatch(r"[\x20-\x7e]*", ln) for ln in mesh.split("\n"))
            assert "PWNED" not in mesh.replace("_touch_PWNED", "")


def test_input_lines_splits_like_lammps():
    text = "units lj\r\n# a \u2028 b\nrun 1\n"
    with pytest.raises(RunError, match=r"s\.lammps:2: .*\\u2028"):
        input_lines(text, "s.lammps")
    assert input_lines("units lj\r\n# a \x0b\x0c b\rc\nrun 1\n") == ["units lj", "# a \x0b\x0c b\rc", "run 1"]
    for bad, why in (("# x &\nrun 1\n", "'&'"), ("# x & \t\nrun 1\n", "'&'"),
                     ('# B"""\nrun 1\n', "string"), ("run 1\x00\n", "C string"),
                     ("# \x85 x\n", "x85"), ("# \x1c\n", "x1c")):
        with pytest.raises(RunError, match=why):
            input_lines(bad, "s.lammps")
    assert input_lines('print """a b"""\n') == ['print """a b"""']
    # every character Python splits on but LAMMPS does not is refused
    for c in range(0x110000):
        ch = chr(c)
        if (ch.isspace() and ch not in " \t\n\v\f\r") or ch == "\0":
            with pytest.raises(RunError):
                input_lines(f"run 1{ch}0\n")
