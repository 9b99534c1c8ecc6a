"""Compares the ctypes mirrors with the layout description the Rust side
writes (`layout.json`): every struct's size, alignment and iceoryx2 type
name, every field's name, offset, size, alignment and type in declaration
order, and every constant. A mismatch is named `Struct.field: what`.

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
    return out


def main() -> int:
    from . import layout

    description = load_description(sys.argv[1] if len(sys.argv) > 1 else None)
    problems = compare(description, layout)
    for p in problems:
        print(p, file=sys.stderr)
    n = sum(len(s["fields"]) for s in description["structs"])
    if not problems:
        print(f"the ctypes mirrors match the Rust layout description ({n} fields)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
