"""The one gate for user text (file, type, material and geometry names) into LAMMPS files.

LAMMPS reads an input script with ``fgets``: it splits lines on ``\\n`` only, joins a line
whose last printable character is ``&`` to the next one, keeps reading lines while a line
holds an odd number of ``\"\"\"`` (a multi-line string), strips ``#`` comments outside quotes,
substitutes ``$x`` / ``${x}`` / ``$(expr)`` outside quotes, treats ``'`` and ``\"`` as word
quotes and replaces known non-ASCII characters (typographic quotes, ...) by ASCII ones.
Any of these in a name rendered into ``in.lammps`` can run commands (``shell ...``) or make
``lmp -in`` read something else than what ``fibrelmp run`` executes.

Rules (every template and data-file writer follows them):

* user text goes into comments, data-file titles and ``Masses`` comments only through
  :func:`comment_text` (the ``comment`` filter in templates);
* user text used as a LAMMPS word (an ID or a type label) goes through :func:`lammps_word`
  (the ``word`` filter), which refuses what LAMMPS could not read back as the same word;
* the template environment (:func:`template_environment`) checks every value a template
  prints: text that could start a new line, a comment, a variable, a continuation or a
  string (:func:`check_fragment`) raises :class:`UnsafeText` instead of being written.

:func:`input_lines` splits a script into the lines ``lmp -in`` executes, for the in-process
runner, and refuses lines LAMMPS would join with the next one.
"""

from __future__ import annotations

import functools
import numbers
import re
import string
from os import PathLike
from pathlib import Path

from fibrelmp.errors import InputError, RunError

# printable ASCII LAMMPS gives no meaning inside a comment or title; everything else is
# replaced: quotes by a backquote, whitespace (every line separator) by a space, the rest
# (control characters, # $ & \\, non-ASCII) by '_'
_COMMENT_SAFE = frozenset(string.ascii_letters + string.digits + " !%()*+,-./:;<=>?@[]^_`{|}~")
_QUOTES = frozenset("\"'")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
# what a printed value may never contain: outside printable ASCII (line separators, control
# characters, characters LAMMPS replaces by ASCII quotes), comment, variable, continuation,
# escape, single quote; double quotes only in pairs, never three in a row
_FRAGMENT_BAD = re.compile(r"[^\x20-\x7e]|[#$&'\\]|\"\"\"")
# whitespace for C's isspace() (LAMMPS); Python's str.split()/strip() know more: those
# (every str.isspace() character not in _C_SPACE) and NUL (ends a C string) are refused
_C_SPACE = " \t\n\v\f\r"
_ODD_CHARS = re.compile("[\x00\x1c-\x1f\x85\xa0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000]")


class LammpsText(str):
    """A str already made safe by :func:`comment_text` or :func:`lammps_word`."""

    __slots__ = ()


class UnsafeText(ValueError):
    """A template printed a value that is not safe LAMMPS text (a template bug: user text
    must go through the ``comment`` or ``word`` filter)."""


def comment_text(value: object) -> LammpsText:
    """``value`` as text for a LAMMPS comment, data-file title or ``Masses`` comment.

    Never fails: every character but printable ASCII without ``\" ' # $ & \\`` is replaced
    (quotes by a backquote, whitespace including every Unicode line separator by a space,
    anything else by ``_``), so the text stays on its line and means nothing to LAMMPS."""
    if isinstance(value, LammpsText):
        return value
    out = []
    for ch in str(value):
        if ch in _COMMENT_SAFE:
            out.append(ch)
        elif ch in _QUOTES:
            out.append("`")
        elif ch.isspace():          # \n \r \v \f \x1c-\x1f \x85 \u2028 \u2029 ...
            out.append(" ")
        else:
            out.append("_")
    return LammpsText("".join(out))


def lammps_word(value: str, path: str | PathLike | None = None, line: int | None = None,
                what: str = "name") -> LammpsText:
    """``value`` unchanged if LAMMPS can use it as one word (an ID or a type label):
    ``[A-Za-z_][A-Za-z0-9_]*``.  Otherwise an InputError at ``path:line`` that says why."""
    if isinstance(value, str) and _WORD.match(value):
        return LammpsText(value)
    raise InputError(path, line, f"{what} {value!r} cannot be used in a LAMMPS script: it must "
                     "start with a letter or '_' and contain only ASCII letters, digits and '_'")


# one argument LAMMPS reads back verbatim: printable ASCII but space " # $ & ' \\
_TOKEN = re.compile(r"[A-Za-z0-9!%()*+,\-./:;<=>?@\[\]^_`{|}~]+\Z")


def lammps_token(value: str) -> LammpsText | None:
    """``value`` unchanged if LAMMPS reads it back as exactly that one argument (printable
    ASCII without whitespace, quotes, ``# $ & \\``), else None: for text a style takes
    verbatim (FibreNet type names written into its files), where the caller has another way
    than refusing the input."""
    if isinstance(value, str) and _TOKEN.match(value):
        return LammpsText(value)
    return None


def lammps_path(value: str | PathLike, what: str = "file") -> LammpsText:
    """A file path as one LAMMPS word (double-quoted when it holds spaces); a path LAMMPS
    could read differently (quotes, ``#``, ``$``, ``&``, backslash, control or non-ASCII
    characters) is a :class:`~fibrelmp.errors.RunError` naming it."""
    text = str(value)
    if not text or _FRAGMENT_BAD.search(text) or '"' in text:
        raise RunError(f"{what} path {text!r} cannot be used in a LAMMPS script (it holds "
                       "characters LAMMPS would interpret); move it to a plain path")
    return LammpsText(f'"{text}"' if " " in text else text)


def check_fragment(value: str) -> str:
    """``value`` if a template may print it verbatim, else :class:`UnsafeText`.

    A safe fragment is printable ASCII without ``# $ & ' \\``, with an even number of
    ``\"`` and no ``\"\"\"``: it cannot end its line, start a comment, substitute a variable,
    continue onto the next line or open a string that swallows the rest of the script."""
    bad = _FRAGMENT_BAD.search(value)
    if bad is not None or value.count('"') % 2:
        what = repr(bad.group()) if bad is not None else "an unpaired '\"'"
        raise UnsafeText(f"unsafe text for a LAMMPS script ({what} in {value!r}): user text "
                         "must go through the 'comment' or 'word' filter")
    return value


def _finalize(value: object) -> object:
    """Jinja finalize: every printed value is a number or a safe fragment."""
    if isinstance(value, (LammpsText, numbers.Number)):     # numpy scalars are Numbers too
        return value
    return check_fragment(str(value))


@functools.lru_cache(maxsize=1)
def template_environment():
    """The jinja2 environment for fibrelmp/templates: ``comment`` and ``word`` filters, and
    a finalize that refuses every printed value :func:`check_fragment` refuses.  One per
    process, so each template is compiled once (jinja reloads a template whose file changed)."""
    from jinja2 import Environment, PackageLoader, StrictUndefined

    env = Environment(loader=PackageLoader("fibrelmp", "templates"), undefined=StrictUndefined,
                      trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
                      finalize=_finalize, autoescape=False)
    env.filters["comment"] = comment_text
    env.filters["word"] = lambda value, what="name": lammps_word(value, None, None, what)
    return env


# ----------------------------------------------------------------------------------------
# reading scripts the way LAMMPS does
def read_script(path: str | PathLike) -> str:
    """A script's text exactly as LAMMPS reads it (no newline translation: a lone ``\\r`` is
    whitespace for LAMMPS, not a line end as for Python's text mode)."""
    try:
        return Path(path).read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RunError(f"{path}: the LAMMPS script is not UTF-8 text ({exc.reason})") from None


def input_lines(text: str, where: str | PathLike = "<script>") -> list[str]:
    """The lines ``lmp -in`` executes, for a runner that passes them one by one.

    Split on ``\\n`` only (a trailing ``\\r`` removed).  A line LAMMPS would join with the next
    one (last printable character ``&``, or an odd number of ``\"\"\"``), or that holds a NUL or a
    character Python's ``str.split`` takes for whitespace but LAMMPS does not, is refused
    (RunError): fibrelmp's templates never write one, so such a script was not written by
    fibrelmp or was edited, and running it line by line would not be what ``lmp -in`` runs."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    out = []
    for number, line in enumerate(lines, 1):
        if line.endswith("\r"):
            line = line[:-1]
        problem = None
        odd = _ODD_CHARS.search(line)
        if line.rstrip(_C_SPACE).endswith("&"):
            problem = "ends in '&' (LAMMPS joins the next line to it)"
        elif line.count('"""') % 2:
            problem = "opens a '\"\"\"' string (LAMMPS reads on to its end)"
        elif odd is not None:
            problem = (f"holds {odd.group()!r}, " + ("which ends a C string" if odd.group() == "\0" else
                       "a line break or space for Python but not for LAMMPS"))
        if problem is not None:
            raise RunError(f"{where}:{number}: refusing to run this script: the line {problem}")
        out.append(line)
    return out
