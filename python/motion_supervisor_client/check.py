"""Compares the ctypes classes with the layout description the Rust side
writes (`layout.json`): every struct's size, alignment and iceoryx2 type
name, every field's name, offset, size, alignment and type in declaration
order (as ctypes lays them out, which is what a reader of shared memory
gets), every constant, and every status row's property (it reads its own
place). A mismatch is named `Struct.field: what`.

    python -m motion_supervisor_client.check     # exit 1 on any mismatch
"""

import ctypes
import json
import sys
from pathlib import Path

#: ctypes' fixed-size types as the description spells them.
_PRIMITIVES = {
    ctypes.c_uint8: "u8",
    ctypes.c_uint16: "u16",
    ctypes.c_uint32: "u32",
    ctypes.c_uint64: "u64",
    ctypes.c_float: "f32",
    ctypes.c_double: "f64",
}


def load_description(path=None) -> dict:
    """The description installed with the package (or the file `path`)."""
    path = Path(path) if path else Path(__file__).with_name("layout.json")
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def wire_type(t) -> str:
    """A ctypes type as the description spells it: `u32`, `[u8; 32]`,
    `AxisAnswer`."""
    if t in _PRIMITIVES:
        return _PRIMITIVES[t]
    if issubclass(t, ctypes.Array):
        return f"[{wire_type(t._type_)}; {t._length_}]"
    if issubclass(t, ctypes.Structure):
        return t.__name__
    return f"unsupported ctypes type {t.__name__}"


def describe(struct) -> dict:
    """What ctypes made of `struct`, in the description's shape."""
    fields = []
    for name, t in struct._fields_:
        cfield = getattr(struct, name)
        fields.append(
            {
                "name": name,
                "offset": cfield.offset,
                "size": cfield.size,
                "align": ctypes.alignment(t),
                "type": wire_type(t),
            }
        )
    type_name = struct.type_name() if hasattr(struct, "type_name") else None
    return {
        "name": struct.__name__,
        "type_name": type_name,
        "size": ctypes.sizeof(struct),
        "align": ctypes.alignment(struct),
        "fields": fields,
    }


def _compare_struct(want: dict, got: dict) -> list:
    name = want["name"]
    out = [
        f"{name}: {key} is {got[key]!r} in Python, {want[key]!r} in Rust"
        for key in ("type_name", "size", "align")
        if got[key] != want[key]
    ]
    want_names = [f["name"] for f in want["fields"]]
    got_names = [f["name"] for f in got["fields"]]
    out += [f"{name}.{n}: missing in Python" for n in want_names if n not in got_names]
    out += [f"{name}.{n}: not in the Rust type" for n in got_names if n not in want_names]
    common = [n for n in want_names if n in got_names]
    if [n for n in got_names if n in want_names] != common:
        out.append(f"{name}: the fields are in another order than in Rust ({', '.join(got_names)})")
    by_name = {f["name"]: f for f in got["fields"]}
    for w in want["fields"]:
        g = by_name.get(w["name"])
        if g is None:
            continue
        for key in ("offset", "size", "align", "type"):
            if g[key] != w[key]:
                out.append(f"{name}.{w['name']}: {key} is {g[key]!r} in Python, {w[key]!r} in Rust")
    return out


def compare(description: dict, module) -> list:
    """Every difference between `description` and the mirrors and
    constants of `module` (empty: they agree field by field)."""
    out = []
    described = set()
    for want in description["structs"]:
        described.add(want["name"])
        struct = getattr(module, want["name"], None)
        if struct is None:
            out.append(f"{want['name']}: no ctypes mirror")
            continue
        out += _compare_struct(want, describe(struct))
    for struct in getattr(module, "MIRRORS", ()):
        if struct.__name__ not in described:
            out.append(f"{struct.__name__}: a mirror of no described Rust type")
    for name, value in description["constants"].items():
        got = getattr(module, name, None)
        if got != value:
            out.append(f"constant {name}: {got!r} in Python, {value!r} in Rust")
    out += _compare_status(description.get("status"), module)
    return out


def _compare_status(status, module) -> list:
    """Every status row is a property of the entry reading its place: a
    flag row sees only its own bit, a number or integer row only its slot."""
    if status is None:
        return ["the description has no status table"]
    entry = getattr(module, status["entry"], None)
    if entry is None:
        return []  # named above as a missing mirror
    out = []
    for row in status["rows"]:
        name, place = row["name"], row["place"]
        if not isinstance(getattr(entry, name, None), property):
            out.append(f"{status['entry']}.{name}: no property for the status row")
            continue
        e = entry()
        area = getattr(e, row["area"])
        if row["area"] == "flags":
            e.flags = 1 << place
            others = [r["name"] for r in status["rows"] if r["type"] == "flag" and r is not row]
            ok = getattr(e, name) is True and not any(getattr(e, n, False) for n in others)
        else:
            area[place] = 1
            got = getattr(e, name)
            ok = got == (row["enum"][1] if row["type"] == "enum" else 1)
        if not ok:
            out.append(f"{status['entry']}.{name}: does not read {row['area']} place {place}")
    return out


def main() -> int:
    from . import layout

    description = load_description(sys.argv[1] if len(sys.argv) > 1 else None)
    problems = compare(description, layout)
    for p in problems:
        print(p, file=sys.stderr)
    n = sum(len(s["fields"]) for s in description["structs"])
    if not problems:
        rows = len(description["status"]["rows"])
        print(f"the ctypes classes match the Rust layout description ({n} fields, {rows} status rows)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
