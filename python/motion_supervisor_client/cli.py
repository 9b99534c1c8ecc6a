"""`motion-client`: the status of every axis, and one operation.

    motion-client --prefix motion              # status
    motion-client --prefix motion --home X     # home X, wait, print the result
    motion-client --prefix motion --enable X
    motion-client --prefix motion --jog X --speed -2 --for 1.5
    motion-client --prefix motion --move X --to 12.5
    motion-client --prefix motion --reset X
    motion-client --prefix motion --stop X     # (--stop all: every axis)
    motion-client --prefix motion --unhome X
    motion-client --prefix motion --redefine X --to 0   # (or --by D): no motion

Exit codes: 0 done (--home: the axis homed with PC set; --move: at its
target; --jog: ended without an axis fault), 1 refused or failed, 3 no
supervisor running under the prefix.
"""

import argparse
import sys

from .paths import default_runtime_dir
from .layout import text


def show(frame) -> None:
    """One line per I/O process and per axis."""
    ios = [text(frame.ios[k].name) for k in range(frame.io_count)]
    for io in frame.ios[: frame.io_count]:
        print(f"io {text(io.name)}: {'attached' if io.attached else 'NOT attached'}")
    for a in frame.axes[: frame.axis_count]:
        bits = " ".join(n.upper() for n in ("en", "dn", "er", "ip", "pc") if getattr(a, n))
        pos = _number(a.position, 4)
        io = ios[a.io] if a.io < len(ios) else "?"
        print(
            f"{text(a.name):<8} io {io:<6} phase {text(a.phase):<12} [{bits}] "
            f"homed {'yes' if a.homed else 'no'} ERR {a.err}/{a.exerr} position {pos}"
        )


def refused(what: str, r) -> int:
    """A refused request: why, and each axis's reason and codes."""
    from .client import refusals

    print(f"{what} refused: {text(r.message)}", file=sys.stderr)
    for name, reason, err, exerr in refusals(r):
        print(f"  {name}: reason {reason} ERR {err}/{exerr}", file=sys.stderr)
    return 1


def _er(e) -> int:
    return int(e.er)


def _number(x, digits: int) -> str:
    """A status number (`-`: none)."""
    return "-" if x is None else f"{x:.{digits}f}"


def home(sup, axis: str, timeout: float) -> int:
    from .client import accepted

    r = sup.home([axis])
    if not accepted(r):
        return refused(f"home {axis}", r)
    print(f"home {axis}: accepted (cycle {r.cycle})")
    try:
        a = sup.wait_homed(axis, r, timeout)
    except TimeoutError as e:
        print(e, file=sys.stderr)
        return 1
    ok = a.pc and a.homed and not a.er
    print(
        f"{axis}: {'homed' if ok else 'NOT homed'}: PC {int(a.pc)} "
        f"ER {_er(a)} ERR {a.err}/{a.exerr} event_raw {_number(a.event_raw, 6)} "
        f"position {_number(a.position, 6)} raw {_number(a.raw, 6)} in {a.elapsed_s:.3f} s"
    )
    return 0 if ok else 1


def operation(what: str, r) -> int:
    """enable / disable / reset / stop / unhome / redefine: every axis's answer."""
    from .client import accepted

    if not accepted(r):
        return refused(what, r)
    print(f"{what}: {' '.join(text(a.name) for a in r.axes[: r.axis_count])}")
    return 0


def move(sup, axis: str, target: float, relative: bool, speed: float, timeout: float) -> int:
    """MAM: move, follow, exit 0 only at the target (PC)."""
    from .client import accepted

    r = sup.move(axis, target, relative=relative, speed=speed)
    if not accepted(r):
        return refused("move", r)
    ok = True
    for e, op in sup.follow(r, timeout):
        pc = e.op_id == op and e.op_pc
        ok = ok and pc and not e.er
        print(f"{text(e.name)}: PC {int(pc)} ER {_er(e)} ERR {e.err}/{e.exerr} position {_number(e.position, 6)}")
    return 0 if ok else 1


def jog(sup, axis: str, speed: float, duration: float) -> int:
    """MAJ, hold to run: a 500 ms lease renewed every 100 ms for `duration`
    seconds, then the jog is ended (only this jog) and followed to rest."""
    from .client import accepted

    with sup.jog(axis, speed, lease=0.5) as j:
        if not accepted(j.answer):
            return refused("jog", j.answer)
        if not j.hold(duration):
            print("the jog ended by itself (stop, limit, fault)")
    ok = True
    for e, _ in sup.follow(j.answer, 30.0):
        ok = ok and not e.er
        print(f"{text(e.name)}: ER {_er(e)} ERR {e.err}/{e.exerr} position {_number(e.position, 6)}")
    return 0 if ok else 1


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="motion-client", description="A client of a running motion-supervisor.")
    p.add_argument("--prefix", default="motion", help="the supervisor's service prefix")
    p.add_argument("--runtime-dir", default=default_runtime_dir(), help="where its session file is")
    p.add_argument("--home", metavar="AXIS", help="home AXIS and wait for the result")
    p.add_argument("--enable", metavar="AXIS", help="MSO: enable the drive of AXIS")
    p.add_argument("--disable", metavar="AXIS", help="MSF: disable the drive of AXIS")
    p.add_argument("--reset", metavar="AXIS", help="MAFR: clear the axis fault of AXIS")
    p.add_argument("--stop", metavar="AXIS", help="MAS: stop AXIS ('all': every axis)")
    p.add_argument("--unhome", metavar="AXIS", help="clear HomedStatus of AXIS ('all': every axis)")
    p.add_argument("--jog", metavar="AXIS", help="MAJ: jog AXIS at --speed for --for seconds")
    p.add_argument("--move", metavar="AXIS", help="MAM: move AXIS --to P (or --by D)")
    p.add_argument("--redefine", metavar="AXIS",
                   help="MRP: the position of AXIS becomes --to P (or moves --by D), without motion")
    p.add_argument("--speed", type=float, default=float("nan"))
    p.add_argument("--to", type=float)
    p.add_argument("--by", type=float)
    p.add_argument("--for", dest="duration", type=float, default=1.0)
    p.add_argument("--timeout", type=float, default=60.0)
    return p


def connect(prefix: str, runtime_dir: str):
    """The supervisor under `prefix` (iceoryx2 logging warnings only), or
    None after saying why there is none (a command then exits 3)."""
    import iceoryx2 as iox2

    from .client import NoSupervisor, Supervisor

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    try:
        return Supervisor(prefix, runtime_dir)
    except NoSupervisor as e:
        print(e, file=sys.stderr)
        return None


def main(argv=None) -> int:
    a = parser().parse_args(argv)
    sup = connect(a.prefix, a.runtime_dir)
    if sup is None:
        return 3
    show(sup.status())
    if a.home:
        return home(sup, a.home, a.timeout)
    for what, op, axis in (("enable", sup.enable, a.enable), ("disable", sup.disable, a.disable),
                           ("reset", sup.reset, a.reset), ("stop", sup.stop, a.stop),
                           ("unhome", sup.unhome, a.unhome)):
        if axis:
            return operation(what, op([] if axis == "all" else [axis]))
    if a.jog:
        return jog(sup, a.jog, a.speed, a.duration)
    if a.move or a.redefine:
        relative = a.to is None
        if relative and a.by is None:
            print(f"--{'move' if a.move else 'redefine'} needs --to P or --by D", file=sys.stderr)
            return 1
        value = a.by if relative else a.to
        if a.redefine:
            return operation("redefine", sup.redefine(a.redefine, value, relative=relative))
        return move(sup, a.move, value, relative, a.speed, a.timeout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
