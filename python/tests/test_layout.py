"""The ctypes classes (built from the layout description the Rust side
writes: crates/control/tests/wire_layout.rs, which fails when layout.json
is stale) against that description: field by field, every status row's
property, and the check itself against deliberately wrong classes and
descriptions.

    cd python && python -m unittest discover -s tests -v
"""

import copy
import ctypes
import types
import unittest

from motion_supervisor_client import check, layout


def mirrors_with(**replaced):
    """The layout module's namespace with some mirrors replaced."""
    ns = dict(vars(layout))
    ns.update(replaced)
    ns["MIRRORS"] = tuple(replaced.get(m.__name__, m) for m in layout.MIRRORS)
    return types.SimpleNamespace(**ns)


def struct_like(base, name=None, fields=None, **extra):
    """A ctypes struct named like `base` with `fields` (default: base's)."""
    attrs = {"_fields_": fields if fields is not None else list(base._fields_)}
    attrs.update(extra)
    if hasattr(base, "type_name") and "type_name" not in extra:
        attrs["type_name"] = staticmethod(base.type_name)
    return type(name or base.__name__, (ctypes.Structure,), attrs)


def swap(fields, a, b):
    """`fields` with the names of fields `a` and `b` swapped (same types)."""
    names = {a: b, b: a}
    return [(names.get(n, n), t) for n, t in fields]


class TheMirrorsMatchRust(unittest.TestCase):
    def setUp(self):
        self.description = check.load_description()

    def test_every_struct_field_and_constant_matches(self):
        self.assertEqual(check.compare(self.description, layout), [])

    def test_every_rust_wire_struct_is_described_and_mirrored(self):
        names = [s["name"] for s in self.description["structs"]]
        for expected in ("ControlRequest", "ControlResponse", "AxisAnswer", "StatusFrame", "AxisStatusEntry",
                         "IoStatusEntry", "IoCounters", "GapCounts", "StreamCounts", "SetpointFrame",
                         "SetpointAxis"):
            self.assertIn(expected, names)
        self.assertEqual(sorted(names), sorted(m.__name__ for m in layout.MIRRORS))

    def test_each_field_is_compared_by_offset_size_and_type(self):
        n = 0
        for s in self.description["structs"]:
            struct = getattr(layout, s["name"])
            for f in s["fields"]:
                cfield = getattr(struct, f["name"])
                with self.subTest(field=f"{s['name']}.{f['name']}"):
                    self.assertEqual(cfield.offset, f["offset"])
                    self.assertEqual(cfield.size, f["size"])
                    self.assertEqual(check.wire_type(dict(struct._fields_)[f["name"]]), f["type"])
                n += 1
        self.assertGreater(n, 100)

    def test_the_service_types_carry_the_rust_type_names(self):
        for s in self.description["structs"]:
            if s["type_name"] is not None:
                self.assertEqual(getattr(layout, s["name"]).type_name(), s["type_name"])


class AWrongMirrorFails(unittest.TestCase):
    """What iceoryx2's own check (type name, size, alignment) lets through,
    this one does not."""

    def setUp(self):
        self.description = check.load_description()

    def problems(self, **replaced):
        return check.compare(self.description, mirrors_with(**replaced))

    def test_swapped_fields_of_the_same_size(self):
        wrong = struct_like(layout.AxisAnswer, fields=swap(layout.AxisAnswer._fields_, "err", "exerr"))
        self.assertEqual(ctypes.sizeof(wrong), ctypes.sizeof(layout.AxisAnswer))
        p = self.problems(AxisAnswer=wrong)
        self.assertTrue(any(x.startswith("AxisAnswer: the fields are in another order") for x in p), p)
        self.assertTrue(any(x.startswith("AxisAnswer.err: offset is 36") for x in p), p)

    def test_a_wrong_field_type_of_the_same_size(self):
        fields = [(n, ctypes.c_int32 if n == "op_id" else t) for n, t in layout.AxisAnswer._fields_]
        wrong = struct_like(layout.AxisAnswer, fields=fields)
        p = self.problems(AxisAnswer=wrong)
        self.assertTrue(any(x.startswith("AxisAnswer.op_id: type is 'unsupported") for x in p), p)

    def test_a_float_for_an_integer(self):
        fields = [(n, ctypes.c_float if n == "spawn_restarts" else t) for n, t in layout.IoStatusEntry._fields_]
        p = self.problems(IoStatusEntry=struct_like(layout.IoStatusEntry, fields=fields))
        self.assertIn("IoStatusEntry.spawn_restarts: type is 'f32' in Python, 'u32' in Rust", p)

    def test_a_wider_field_moves_the_rest(self):
        fields = [(n, ctypes.c_uint32 if n == "reason" else t) for n, t in layout.AxisAnswer._fields_]
        p = self.problems(AxisAnswer=struct_like(layout.AxisAnswer, fields=fields))
        self.assertIn("AxisAnswer.reason: size is 4 in Python, 1 in Rust", p)
        self.assertIn("AxisAnswer.err: offset is 40 in Python, 34 in Rust", p)

    def test_a_missing_and_an_extra_field(self):
        fields = [(n, t) for n, t in layout.StreamCounts._fields_ if n != "owners"] + [("spare", ctypes.c_uint32)]
        p = self.problems(StreamCounts=struct_like(layout.StreamCounts, fields=fields))
        self.assertIn("StreamCounts.owners: missing in Python", p)
        self.assertIn("StreamCounts.spare: not in the Rust type", p)

    def test_a_short_array(self):
        fields = [(n, ctypes.c_uint8 * 31 if n == "owner" else t) for n, t in layout.ControlRequest._fields_]
        p = self.problems(ControlRequest=struct_like(layout.ControlRequest, fields=fields))
        self.assertIn("ControlRequest.owner: type is '[u8; 31]' in Python, '[u8; 32]' in Rust", p)

    def test_a_nested_struct_checked_through_its_own_fields(self):
        wrong = struct_like(layout.SetpointAxis, fields=swap(layout.SetpointAxis._fields_, "position", "velocity"))
        p = self.problems(SetpointAxis=wrong)
        self.assertIn("SetpointAxis.position: offset is 16 in Python, 8 in Rust", p)

    def test_a_wrong_type_name(self):
        wrong = struct_like(layout.StatusFrame, type_name=staticmethod(lambda: "motion_control::StatusFrame@3"))
        p = self.problems(StatusFrame=wrong)
        self.assertTrue(any(x.startswith("StatusFrame: type_name is 'motion_control::StatusFrame@3'") for x in p), p)

    def test_a_missing_mirror_and_a_wrong_constant(self):
        ns = mirrors_with()
        del ns.SetpointAxis
        ns.REQ_MOVE = 15
        p = check.compare(self.description, ns)
        self.assertIn("SetpointAxis: no ctypes mirror", p)
        self.assertIn("constant REQ_MOVE: 15 in Python, 14 in Rust", p)


class AChangedRustTypeFails(unittest.TestCase):
    """A description as the Rust side would write it after a change the
    mirrors did not follow."""

    def setUp(self):
        self.description = check.load_description()

    def mutated(self, struct, field=None, **changes):
        d = copy.deepcopy(self.description)
        s = next(s for s in d["structs"] if s["name"] == struct)
        target = s if field is None else next(f for f in s["fields"] if f["name"] == field)
        target.update(changes)
        return check.compare(d, layout)

    def test_each_attribute_of_a_field(self):
        self.assertIn("ControlRequest.lease_ms: offset is 112 in Python, 116 in Rust",
                      self.mutated("ControlRequest", "lease_ms", offset=116))
        self.assertIn("AxisStatusEntry.flags: size is 8 in Python, 4 in Rust",
                      self.mutated("AxisStatusEntry", "flags", size=4))
        self.assertIn("AxisStatusEntry.flags: align is 8 in Python, 4 in Rust",
                      self.mutated("AxisStatusEntry", "flags", align=4))
        self.assertIn("StatusFrame.cycle: type is 'u64' in Python, 'i64' in Rust",
                      self.mutated("StatusFrame", "cycle", type="i64"))

    def test_a_renamed_field(self):
        p = self.mutated("SetpointFrame", "t_ns", name="time_ns")
        self.assertIn("SetpointFrame.time_ns: missing in Python", p)
        self.assertIn("SetpointFrame.t_ns: not in the Rust type", p)

    def test_the_struct_itself(self):
        self.assertIn("ControlResponse: size is 36160 in Python, 36168 in Rust",
                      self.mutated("ControlResponse", size=36168))
        self.assertIn("StatusFrame: type_name is 'motion_control::StatusFrame@4' in Python, "
                      "'motion_control::StatusFrame@5' in Rust",
                      self.mutated("StatusFrame", type_name="motion_control::StatusFrame@5"))

    def test_a_new_struct_without_a_mirror(self):
        d = copy.deepcopy(self.description)
        d["structs"].append({"name": "NewThing", "type_name": None, "size": 8, "align": 8, "fields": []})
        self.assertIn("NewThing: no ctypes mirror", check.compare(d, layout))


def row(name):
    return next(r for r in layout.STATUS_ROWS if r["name"] == name)


class TheStatusRowsAreProperties(unittest.TestCase):
    """Each row of the status table reads its own place of an entry, typed
    as the row says; the names programs use are there."""

    def test_the_names_programs_use(self):
        e = layout.AxisStatusEntry()
        for name in ("name", "position", "cmd_position", "err", "exerr", "homed", "pc", "er", "jogging"):
            self.assertTrue(hasattr(e, name), name)
        self.assertEqual(layout.text(e.name), "")

    def test_each_type_reads_its_place(self):
        e = layout.AxisStatusEntry()
        e.flags = 1 << row("homed")["place"]
        self.assertIs(e.homed, True)
        self.assertIs(e.homing, False)
        e.values[row("position")["place"]] = float("nan")
        self.assertIsNone(e.position)
        e.values[row("position")["place"]] = 12.5
        self.assertEqual(e.position, 12.5)
        e.ints[row("err")["place"]] = 12
        self.assertEqual(e.err, 12)
        e.ints[row("op_kind")["place"]] = row("op_kind")["enum"].index("jog")
        self.assertEqual(e.op_kind, "jog")
        e.ints[row("op_kind")["place"]] = 250
        self.assertEqual(e.op_kind, "?")
        e.flags = 1 << row("moving")["place"]
        self.assertTrue(e.in_motion)

    def test_a_property_reading_another_place_is_caught(self):
        entry = layout.AxisStatusEntry
        wrong = struct_like(entry, **{"homed": property(lambda self: bool(self.flags & 1)),
                                      "position": property(lambda self: self.values[0 if row("position")["place"] else 1])})
        for r in layout.STATUS_ROWS:
            if r["name"] not in ("homed", "position"):
                setattr(wrong, r["name"], getattr(entry, r["name"]))
        ns = mirrors_with(AxisStatusEntry=wrong)
        p = check.compare(check.load_description(), ns)
        self.assertIn("AxisStatusEntry.homed: does not read flags place 6", p)
        self.assertIn(f"AxisStatusEntry.position: does not read values place {row('position')['place']}", p)

    def test_a_row_without_a_property_is_caught(self):
        d = copy.deepcopy(check.load_description())
        d["status"]["rows"].append(dict(row("homed"), name="latched", place=63))
        self.assertIn("AxisStatusEntry.latched: no property for the status row", check.compare(d, layout))

    def test_a_new_row_becomes_a_property_without_a_line_of_python(self):
        d = copy.deepcopy(check.load_description())
        d["status"]["rows"].append(dict(row("position"), name="latched_position", place=31, json="latched_position"))
        classes = layout._build(d)
        e = classes["AxisStatusEntry"]()
        e.values[31] = 2.5
        self.assertEqual(e.latched_position, 2.5)


if __name__ == "__main__":
    unittest.main()
