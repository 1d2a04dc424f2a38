"""Whole-document conversion between MUSEN's two file forms (``fibrelmp convert``).

A document is a scene message plus time points (``Document``).  ``MdemDocument`` and
``MusenTextDocument`` are the registry's ``document`` hooks of the ``mdem`` and ``musen``
formats: ``open`` reads a file as a document, ``writer`` gives the Writer that writes one.

* ``.mdem`` -> text: MUSEN's ``EXPORT_TO_TEXT`` (``text_export``);
* text -> ``.mdem``: MUSEN's ``IMPORT_FROM_TEXT`` (``text_import``);
* ``.mdem`` -> ``.mdem``: the file again, byte for byte (``MdemFile.copy_to``);
* text -> text: through a temporary ``.mdem``, i.e. import then export, as MUSEN would.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, ClassVar, Iterator

from fibrelmp.formatbase import DocumentFormat, Writer


@dataclass
class Document:
    """A MUSEN scene/result: its scene message and a way to iterate its time points."""

    path: Path
    storage: Any
    points: Callable[[], Iterator]
    mdem: Any = None                       # the open MdemFile when read from a .mdem

    def close(self) -> None:
        if self.mdem is not None:
            self.mdem.close()


class MdemDocument(DocumentFormat):
    suffixes: ClassVar[tuple[str, ...]] = (".mdem",)

    @staticmethod
    def open(path: Path) -> Document:
        from fibrelmp.translate.musen.mdem.document import MdemFile

        mdem = MdemFile(path)
        return Document(Path(path), mdem.scene, mdem.time_points, mdem)

    @staticmethod
    def writer(target: Path, precision: int | None = None, *, force: bool = False) -> Writer:
        return MdemDocumentWriter(target, force=force)


class MusenTextDocument(DocumentFormat):
    suffixes: ClassVar[tuple[str, ...]] = (".txt",)
    takes_precision: ClassVar[bool] = True

    @staticmethod
    def open(path: Path) -> Document:
        from fibrelmp.translate.musen.mdem.text_import import import_text

        storage, points = import_text(path)
        return Document(Path(path), storage, lambda: points)

    @staticmethod
    def writer(target: Path, precision: int | None = None, *, force: bool = False) -> Writer:
        return MusenTextWriter(target, 6 if precision is None else precision, force=force)


class MdemDocumentWriter(Writer):
    """``add(document)`` once: the document as a ``.mdem`` file."""

    format = "mdem"

    def write(self, doc: Document) -> None:
        from fibrelmp.translate.musen.mdem.document import MdemWriter

        fh = self.open(self.target, "w+b")
        if doc.mdem is not None:
            doc.mdem.copy_to(fh)
            return
        out = MdemWriter(fh)
        for time, values, masks in doc.points():
            out.add(time, values, masks)
        out.finish(doc.storage)


class MusenTextWriter(Writer):
    """``add(document)`` once: the document as MUSEN text (``precision`` digits for
    time-point values)."""

    format = "musen"

    def __init__(self, target: str | os.PathLike, precision: int = 6, *, force: bool = True):
        super().__init__(target, force=force)
        self.precision = precision

    def write(self, doc: Document) -> None:
        from fibrelmp.translate.musen.mdem.document import MdemFile
        from fibrelmp.translate.musen.mdem.text_export import export

        out = self.open(self.target, "w", newline="\n")
        if doc.mdem is not None:
            export(doc.mdem, out, self.precision, spool_dir=self.target.parent)
            return
        with tempfile.TemporaryDirectory(prefix=".fibrelmp-convert.", dir=self.target.parent) as tmp:
            binary = Path(tmp) / "document.mdem"
            with MdemDocumentWriter(binary) as w:
                w.add(doc)
            with MdemFile(binary) as mdem:
                export(mdem, out, self.precision, spool_dir=Path(tmp))
