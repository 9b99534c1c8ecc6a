"""ctypes classes of the supervisor's wire structs and their numbers, built
at import from the layout description the Rust side writes (`layout.json`,
installed with this package).

The description (written by crates/control/tests/wire_layout.rs from the
Rust types themselves, which fails when the checked-in file is stale) has
every struct's fields with their types, every constant, and the status
table: where each field of an axis's status lives in a status entry (a bit
of its `flags` word, a slot of its `ints` or `values` area). So nothing is
restated here: a struct becomes a ctypes class of the same name, a constant
a module name, a status row a property of `AxisStatusEntry`
(`entry.homed`, `entry.position`, `entry.err`, ...). `check.py` then
compares what ctypes made of the classes (offsets, sizes, alignments) with
the description field by field: iceoryx2 itself only compares a type's
name, size and alignment when a service is opened.

A status row's property: a flag is a bool; a `value` a float; a `maybe` a
float or None (no valid feedback, nothing latched); an integer an int; an
enumeration its name (`"jog"`, `"lease_expired"`; "?" for a number this
description does not know). A newer supervisor's rows that this
description does not have are simply not there.

This module needs nothing but the standard library.
"""

import ctypes
import json
import math
from pathlib import Path

#: The description this package was built against.
DESCRIPTION = json.loads(Path(__file__).with_name("layout.json").read_text(encoding="utf-8"))

_PRIMITIVES = {
    "u8": ctypes.c_uint8,
    "u16": ctypes.c_uint16,
    "u32": ctypes.c_uint32,
    "u64": ctypes.c_uint64,
    "f32": ctypes.c_float,
    "f64": ctypes.c_double,
}


def _ctype(spelled: str, classes: dict):
    """A field type as the description spells it (`u32`, `[u8; 32]`,
    `[[u8; 32]; 64]`, `AxisAnswer`) as a ctypes type."""
    if spelled.startswith("["):
        inner, n = spelled[1:-1].rsplit(";", 1)
        return _ctype(inner.strip(), classes) * int(n)
    return _PRIMITIVES.get(spelled) or classes[spelled]


def _structure(s: dict, classes: dict):
    attrs = {"_fields_": [(f["name"], _ctype(f["type"], classes)) for f in s["fields"]]}
    if s["type_name"] is not None:
        name = s["type_name"]
        attrs["type_name"] = staticmethod(lambda: name)
    return type(s["name"], (ctypes.Structure,), attrs)


def _row_property(row: dict):
    """The property reading one status row from an entry."""
    place, kind = row["place"], row["type"]
    if kind == "flag":
        def get(self):
            return bool(self.flags >> place & 1)
    elif kind == "value":
        def get(self):
            return self.values[place]
    elif kind == "maybe":
        def get(self):
            v = self.values[place]
            return v if math.isfinite(v) else None
    elif kind == "enum":
        names = row["enum"]

        def get(self):
            n = self.ints[place]
            return names[n] if n < len(names) else "?"
    else:
        def get(self):
            return self.ints[place]
    return property(get, doc=row["doc"])


def _build(description: dict) -> dict:
    classes = {}
    for s in description["structs"]:  # nested structs come first
        classes[s["name"]] = _structure(s, classes)
    status = description["status"]
    entry = classes[status["entry"]]
    for row in status["rows"]:
        setattr(entry, row["name"], _row_property(row))
    motion = description["constants"]["IN_MOTION"]
    entry.in_motion = property(lambda self: bool(self.flags & motion), doc="A jog, a move or a stream moves the axis.")
    return classes


globals().update(DESCRIPTION["constants"])
globals().update(_build(DESCRIPTION))

#: Every class built from the description, named like its Rust type.
MIRRORS = tuple(v for v in list(globals().values()) if isinstance(v, type) and issubclass(v, ctypes.Structure))

#: The status table's rows (name, type, place, unit, JSON key, OPC UA name, doc).
STATUS_ROWS = tuple(DESCRIPTION["status"]["rows"])


def text(arr) -> str:
    """The text of a NUL-padded byte field (invalid UTF-8 replaced)."""
    return bytes(arr).split(b"\0", 1)[0].decode("utf-8", "replace")


def put_text(arr, s: str) -> None:
    """Writes `s` NUL-padded into the byte field `arr` (cut to fit, at a
    character boundary, like the Rust side's `put_str`)."""
    raw = s.encode()[: len(arr)]
    while raw:
        try:
            raw.decode()
            break
        except UnicodeDecodeError:
            raw = raw[:-1]
    ctypes.memset(arr, 0, len(arr))
    ctypes.memmove(arr, raw, len(raw))
