"""MUSEN's agglomerates database (``.madb``, the script key ``AGGLOMERATES_DB``) and the
agglomerate a dynamic generator inserts.

A ``.madb`` is one bare ``ProtoAgglomeratesDB`` message (MUSEN's
``Databases/AgglomerateDatabase/AgglomeratesDatabase.proto``; ``CAgglomeratesDatabase::
LoadFromFile``): agglomerates with a key, a type (0 agglomerate, 1 multisphere), spheres
(coordinates, radius, contact radius, compound alias, quaternion) and solid bonds (left and
right sphere index, radius, compound alias).  cmusen loads it after the generators'
configuration and ``CObjectsGenerator::Initialize`` copies the generator's agglomerate,
shifts it so that its volume-weighted centre (running mean, MUSEN's order of operations) is
the origin and multiplies coordinates, radii, contact radii and bond radii by the
generator's ``scaling_factor`` (``prepared_agglomerate`` reproduces that arithmetic).

Reading is bounded: the file is at most ``MAX_BYTES`` and its messages are counted on the
wire before the parse (``bounds.count_messages``): at most one per ``BYTES_PER_MESSAGE``
stored bytes (+ ``MESSAGES_SLACK``), so a hostile file of empty messages cannot make the
parser allocate more than about 1 M messages (~160 MB).
"""

from __future__ import annotations

import math
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError

AGGLOMERATE, MULTISPHERE = 0, 1        # SAgglomerate::nType
MAX_BYTES = 16 << 20                   # MUSEN's shipped database is 1.5 MB
# messages per stored byte: MUSEN's shipped database has one per 27 bytes (a sphere is 3
# messages of ~80 bytes, a bond one of ~25); at most this many, then ~160 bytes each parsed
BYTES_PER_MESSAGE = 16
MESSAGES_SLACK = 4096
_PI = 3.14159265358979323846           # MUSEN's PI (BasicTypes.h)


@dataclass(frozen=True)
class Agglomerate:
    """One agglomerate of the database as stored (sphere coordinates in its own frame)."""

    key: str
    name: str
    kind: int                                  # AGGLOMERATE or MULTISPHERE
    coords: np.ndarray = field(compare=False)  # (n, 3)
    radius: np.ndarray = field(compare=False)  # (n,)
    contact_radius: np.ndarray = field(compare=False)
    part_alias: tuple[str, ...] = ()
    bond_pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64), compare=False)
    bond_radius: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)
    bond_alias: tuple[str, ...] = ()


def read_database(path: Path, where: Path | None = None, line: int | None = None) -> dict[str, Agglomerate]:
    """The agglomerates of the ``.madb`` file ``path`` by key (the first of a repeated key,
    as ``CAgglomeratesDatabase::GetAgglomerate`` finds it).  ``where``/``line``: the script
    line naming the file, for the errors."""
    from fibrelmp.translate.musen.mdem import bounds
    from fibrelmp.translate.musen.mdem.messages import new

    src = where or path
    try:
        info = path.stat()
        # a device or FIFO reports size 0 and may never end: only regular files, read bounded
        if not stat.S_ISREG(info.st_mode):
            raise InputError(src, line, f"agglomerates database {str(path)!r} is not a regular file")
        with path.open("rb") as f:
            data = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise InputError(src, line, f"agglomerates database {str(path)!r}: {exc.strerror}") from None
    if len(data) > MAX_BYTES:
        raise InputError(src, line, f"agglomerates database {str(path)!r} has more than "
                         f"{MAX_BYTES} bytes, more than fibrelmp reads")
    try:
        bounds.count_messages(data, "ProtoAgglomeratesDB", len(data) // BYTES_PER_MESSAGE + MESSAGES_SLACK)
        db = new("ProtoAgglomeratesDB", data)
    except Exception as exc:        # TooMany, a broken wire format, protobuf's DecodeError
        raise InputError(src, line, f"agglomerates database {str(path)!r} is not a MUSEN "
                         f".madb file ({type(exc).__name__}: {exc})") from None
    out: dict[str, Agglomerate] = {}
    for a in db.Agglomerate:
        if a.key in out:
            continue
        parts = a.particles
        coords = np.array([[p.coord.x, p.coord.y, p.coord.z] for p in parts], float).reshape(-1, 3)
        pairs = np.array([[b.leftID, b.rightID] for b in a.bonds], np.int64).reshape(-1, 2)
        out[a.key] = Agglomerate(
            key=a.key, name=a.name, kind=int(a.type), coords=coords,
            radius=np.array([p.radius for p in parts], float),
            contact_radius=np.array([p.contact_radius for p in parts], float),
            part_alias=tuple(p.compound for p in parts), bond_pairs=pairs,
            bond_radius=np.array([b.radius for b in a.bonds], float),
            bond_alias=tuple(b.compound for b in a.bonds))
    return out


def prepared_agglomerate(agg: Agglomerate, scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``CObjectsGenerator::Initialize``: (coordinates, radii, bond diameters) of the
    agglomerate as the generator inserts it before its random rotation: shifted to the
    volume-weighted centre (MUSEN's running mean, its rounding) and scaled; bond diameter =
    2 x scaled bond radius (``AddSolidBond(..., 2 * bond.dRadius)``)."""
    centre = np.zeros(3)
    total = 0.0
    for c, r in zip(agg.coords, agg.radius):
        v = _PI * math.pow(2 * float(r), 3) / 6.0
        centre = (centre * total + c * v) / (v + total)
        total += v
    coords = (agg.coords - centre) * scale
    return coords, agg.radius * scale, 2.0 * (agg.bond_radius * scale)


def write_database(path: Path, agglomerates: list[dict]) -> None:
    """A ``.madb`` as MUSEN's ``SaveToFile`` writes it (used to make test databases): each
    dict has key, name, type, particles [(x, y, z, radius, alias)], bonds [(left, right,
    radius, alias)]; contact radius = radius, quaternion (1, 0, 0, 0) (not MUSEN's default
    (0, 1, 0, 0): its agglomerate editor stores the identity)."""
    from fibrelmp.translate.musen.mdem.messages import new

    db = new("ProtoAgglomeratesDB")
    for spec in agglomerates:
        a = db.Agglomerate.add(key=spec["key"], name=spec["name"], type=spec.get("type", AGGLOMERATE))
        volume = 0.0
        for x, y, z, r, alias in spec["particles"]:
            p = a.particles.add(radius=r, contact_radius=r, compound=alias)
            p.coord.x, p.coord.y, p.coord.z = x, y, z
            p.quaternion.q0 = 1.0
            volume += _PI * math.pow(2 * r, 3) / 6.0
        for left, right, r, alias in spec["bonds"]:
            a.bonds.add(leftID=left, rightID=right, radius=r, compound=alias)
        a.volume = volume          # informative only (MUSEN's CalculateVolume adds the bonds)
    path.write_bytes(db.SerializeToString())
