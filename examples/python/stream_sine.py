#!/usr/bin/env python3
"""Streams a sine to one axis through the supervisor's supervised setpoint
stream, with the Python client package (`pip install ./python`).

    python3 stream_sine.py --prefix motion --axis X --amplitude 2 --hz 0.5 --seconds 4

What a program does to move axes (see README, "The setpoint stream"), here
through `Supervisor.stream` of the package:

1. join the supervisor's domain through its session file (`Supervisor`);
2. take the axis over (REQ_STREAM_ACQUIRE, naming this program's node): the
   answer carries the owner token and the index setpoints address;
3. publish SetpointFrames (layout 1: key, token, an increasing seq, its own
   time t_ns) — here at --rate Hz, and at least every stream_timeout_ms
   (default 50 ms: the axis stops when nothing arrived for that long); the
   supervisor interpolates between them to its cycle, checks every one
   (finite, inside the travel limits, within max_speed and
   stream_acceleration, in time order) and follows them within those
   limits on its own clock;
4. give the axis back (REQ_STREAM_RELEASE): the stream ends, the axis stops
   at once (here at rest on the last setpoint).

The sine starts at the axis's position and at rest (p = p0 + A (1 - cos
2 pi f t)). If this program dies, the supervisor stops the axis.

Exit codes: 0 streamed to the end and released, 1 refused or stopped with an
error, 3 no supervisor running under the prefix.
"""

import argparse
import math
import sys
import time

from motion_supervisor_client import accepted, text
from motion_supervisor_client.cli import connect, refused
from motion_supervisor_client.paths import default_runtime_dir


def stream(sup, a, index, s) -> tuple:
    """Publishes the sine; (ok, largest following error seen)."""
    start = sup.status().axes[index]
    p0 = start.cmd_position if start.cmd_position is not None else start.position
    w = 2.0 * math.pi * a.hz
    period = 1.0 / a.rate
    t0 = time.monotonic_ns()
    worst = 0.0
    for k in range(int(a.seconds * a.rate) + 1):
        t = k * period
        while time.monotonic_ns() < t0 + int(t * 1e9):
            time.sleep(0.0005)
        position = p0 + a.amplitude * (1.0 - math.cos(w * t))
        s.publish([(index, position, a.amplitude * w * math.sin(w * t))], t_ns=t0 + int(t * 1e9))
        if k % 10 == 0:
            st = sup.status().axes[index]
            if st.cmd_position is not None and st.position is not None:
                worst = max(worst, abs(st.cmd_position - st.position))
            if k > 0 and not st.streaming:
                print(f"{a.axis}: the stream stopped: ERR {st.err}/{st.exerr}", file=sys.stderr)
                return False, worst, p0
    return True, worst, p0


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--prefix", default="motion")
    p.add_argument("--runtime-dir", default=default_runtime_dir())
    p.add_argument("--axis", required=True)
    p.add_argument("--amplitude", type=float, default=1.0, help="units")
    p.add_argument("--hz", type=float, default=0.5, help="sine frequency")
    p.add_argument("--seconds", type=float, default=4.0)
    p.add_argument("--rate", type=float, default=100.0, help="setpoints per second")
    a = p.parse_args()
    sup = connect(a.prefix, a.runtime_dir)
    if sup is None:
        return 3
    frame0 = sup.status()
    names = [text(e.name) for e in frame0.axes[: frame0.axis_count]]
    if a.axis not in names:
        print(f"no axis {a.axis} (axes: {', '.join(names)})", file=sys.stderr)
        return 1
    s = sup.stream([a.axis], owner="stream_sine")
    if not accepted(s.answer):
        s.release()
        return refused("stream", s.answer)
    ok, worst, p0 = stream(sup, a, s.index[a.axis], s)
    # The last segment's length, for the axis to reach the last setpoint
    # (the release stops it at once) — not longer: nothing published for
    # stream_timeout_ms stops it with an error.
    time.sleep(1.0 / a.rate)
    # Released: follow the stream ends' operations (their ids are in the
    # answer) to rest; refused: the stream was over already (an error).
    rel = s.release()
    for e, _ in sup.follow(rel if accepted(rel) else s.answer, 30.0):
        ok = ok and not e.er
        print(
            f"{text(e.name)}: ER {int(e.er)} ERR {e.err}/{e.exerr} "
            f"position {'-' if e.position is None else f'{e.position:.6f}'} (started at {p0:.6f}); "
            f"largest following error seen {worst:.6f}"
        )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
