"""A program whose setpoint timestamps claim more time than the cycle gives
it, run against a daemon by tests/python_client.rs (not a unit test: it
needs a supervisor, so unittest's discovery leaves it alone).

    python stream_clock.py --prefix P --axis X --distance 15

It takes AXIS over (homed and enabled) and publishes, through the package,
(t, p0), (t + 1 h, p0 + D), (t + 1 h + 1 ms, p0 + D), each in a cycle of
its own: on the program's clock an hour's slow move and a rest; on the
cycle's, D units in one cycle. Then it watches the status frames for
0.3 s and prints one JSON line: the largest |command - p0| seen, and the
axis's ERR / EXERR and streaming bit at the end.
"""

import argparse
import json
import sys
import time

from motion_supervisor_client import Supervisor, accepted, text

HOUR_NS = 3600 * 10**9


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--prefix", required=True)
    p.add_argument("--axis", required=True)
    p.add_argument("--distance", type=float, default=15.0)
    a = p.parse_args()
    sup = Supervisor(a.prefix, node_name="stream-clock")
    frame = sup.status()
    names = [text(e.name) for e in frame.axes[: frame.axis_count]]
    i = names.index(a.axis)
    p0 = frame.axes[i].cmd_position
    s = sup.stream([a.axis], owner="stream-clock")
    if not accepted(s.answer):
        print(json.dumps({"acquired": False}))
        return 1
    index = s.index[a.axis]
    t0 = time.monotonic_ns()
    for dt, position in [(0, p0), (HOUR_NS, p0 + a.distance), (HOUR_NS + 10**6, p0 + a.distance)]:
        s.publish([(index, position, None)], t_ns=t0 + dt)
        # each in a cycle of its own (the cycle takes a cycle's newest)
        time.sleep(0.005)
    worst = 0.0
    until = time.monotonic() + 0.3
    while time.monotonic() < until:
        e = sup.status().axes[i]
        if e.cmd_position is not None:
            worst = max(worst, abs(e.cmd_position - p0))
        time.sleep(0.002)
    e = sup.status().axes[i]
    s.release()
    print(
        json.dumps(
            {
                "acquired": True,
                "largest_excursion": worst,
                "err": e.err,
                "exerr": e.exerr,
                "streaming": bool(e.streaming),
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
