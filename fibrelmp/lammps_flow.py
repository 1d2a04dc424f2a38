"""The order in which ``lmp -in`` executes a script's commands: loops (``variable V loop N``,
``next V``, ``jump SELF L``) and conditional jumps (``if "COND" then "jump SELF L"``), followed
outside LAMMPS because LAMMPS's own ``jump`` needs an input file (the runner feeds commands)."""

from __future__ import annotations

import shlex
from typing import TYPE_CHECKING, Callable, Iterator

from fibrelmp.errors import RunError

if TYPE_CHECKING:
    from fibrelmp.runner import Command  # noqa: F401

HOLDS_VARIABLE = "fl_jump_holds"     # set by the runner to evaluate a jump's condition
# a script that stops early (MUSEN's stop criterion) says so with a print beginning with this;
# the one frame it writes after it is one step after the last saved one
STOP_PRINT = "stop criterion met"


def is_stop_print(words: list[str]) -> bool:
    """Is this command the print that starts a script's early end (``STOP_PRINT``)?"""
    return words[0] == "print" and " ".join(words[1:]).lstrip('"').startswith(STOP_PRINT)


def jump_target(text: str) -> str | None:
    """The label of ``if "COND" then "jump SELF L"`` (exactly this form), else None."""
    try:
        words = shlex.split(text)
    except ValueError:
        return None
    if len(words) != 4 or words[0] != "if" or words[2] != "then":
        return None
    jump = words[3].split()
    return jump[2] if len(jump) == 3 and jump[:2] == ["jump", "SELF"] else None


def condition_holds(lmp, text: str, where: str) -> bool:
    """LAMMPS's own value of the condition of ``if "COND" then "jump SELF L"`` (every rank
    evaluates it alike: LAMMPS's ``if`` is collective)."""
    cond = shlex.split(text)[1]
    try:
        lmp.command(f'if "{cond}" then "variable {HOLDS_VARIABLE} equal 1" '
                    f'else "variable {HOLDS_VARIABLE} equal 0"')
        return float(lmp.extract_variable(HOLDS_VARIABLE)) == 1.0
    except Exception as exc:       # LAMMPS raises plain Exception subclasses
        raise RunError(f"{where}: LAMMPS error: {str(exc).strip()}") from None


def execute(commands: list["Command"], labels: dict[str, int], where: str = "in.lammps",
            taken: Callable[[], bool] | None = None) -> Iterator["Command"]:
    """The commands in the order LAMMPS executes them, following loops the way ``lmp -in``
    does: ``variable V loop N`` counts, ``next V`` advances (and past N the next ``jump`` is
    skipped), ``jump SELF L`` continues after ``label L``; after a conditional jump is
    yielded, ``taken()`` (the caller's evaluation of it) says whether it jumps.  Yields every
    command (the caller sends all but ``label``/``jump`` to LAMMPS, whose ``next`` keeps its
    own copy in step)."""
    loops: dict[str, list[int]] = {}
    files: set[str] = set()          # atomfile variables: 'next' reads their next block
    skip_jump = False
    pc = 0
    while pc < len(commands):
        cmd = commands[pc]
        pc += 1
        w = cmd.words
        if w[0] == "variable" and len(w) >= 4 and w[2] == "loop":
            lo, hi = (1, int(w[3])) if len(w) == 4 or not w[4].isdigit() else (int(w[3]), int(w[4]))
            loops[w[1]] = [lo, hi]
        elif w[0] == "variable" and len(w) >= 4 and w[2] == "atomfile":
            files.add(w[1])
        elif w[0] == "next" and all(name in files for name in w[1:]):
            pass                     # LAMMPS's own: no loop to follow
        elif w[0] == "next":
            for name in w[1:]:
                state = loops.get(name)
                if state is None:
                    raise RunError(f"{where}:{cmd.number}: 'next {name}' without a loop variable")
                state[0] += 1
                if state[0] > state[1]:
                    del loops[name]
                    skip_jump = True
        elif w[0] == "if" and (target := jump_target(cmd.text)) is not None:
            if target not in labels:
                raise RunError(f"{where}:{cmd.number}: no label {target!r} in this script")
            yield cmd
            if taken is not None and taken():
                pc = labels[target] + 1
            continue
        elif w[0] == "jump":
            yield cmd
            if skip_jump:
                skip_jump = False
                continue
            if len(w) != 3 or w[1] != "SELF" or w[2] not in labels:
                raise RunError(f"{where}:{cmd.number}: only 'jump SELF label' with a label of "
                               "this script is supported")
            pc = labels[w[2]] + 1
            continue
        yield cmd
