#!/usr/bin/env python3
"""What motion-opcua costs the cycle, and how late its notifications are.

    cargo build --release -p motion-supervisor -p motion-io -p motionctl -p motion-opcua
    .ci/venv/bin/python bench/opcua/opcua_bench.py [--slice 20] [--rounds 3] [--samples 150]

(1) Cost: the demo machine plus an immediate-homing axis I, in alternating
slices of the same run: "off" (no motion-opcua; axis I homed and unhomed
twice a second through the iceoryx2 control service) and "on" (motion-opcua
running, an asyncua client subscribed to every live variable of every axis
at 100 ms, the same Home/Unhome twice a second as OPC UA method calls). The
daemon's wake-up and compute p99 per slice (`motionctl stats --json`,
since a reset at the slice's start), and the on/off ratio.

(2) Latency: HomedStatus of I subscribed (sampling 0, publishing 10 ms);
Unhome sent through the control service (iceoryx2, Python client of
examples/python): the cycle that applies it lies between sending and the
answer (a few ms). Latency = the notification's arrival − the middle of
that window: p50/p99, and the window's half width.

Prints one JSON object; the bench, not a test: it judges nothing.
"""

import argparse
import asyncio
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "examples/python"))
sys.path.insert(0, str(ROOT / "crates/opcua/tests"))
import asyncua_client as uac  # noqa: E402
import motion_client as mc  # noqa: E402
from asyncua import ua  # noqa: E402

REQ_HOME, REQ_UNHOME = 1, 3
REL = ROOT / "target/release"

EXTRA_AXIS = """
[[axis]]
name = "I"                  # homed at once, where it stands
home_sequence = "immediate"
home_mode = "active"
home_position = 0.0
home_timeout = 5.0
counts_per_unit = 1000.0
configuration = "servo"
control_mode = "position"
travel = "linear"
marker = false
"""


class Rig:
    def __init__(self, a):
        self.a = a
        self.dir = Path(tempfile.mkdtemp(prefix="opcua-bench-"))
        self.prefix = f"opcuabench{os.getpid()}"
        self.run = f"/tmp/ob{os.getpid()}"
        os.makedirs(self.run, mode=0o700, exist_ok=True)
        port = free_port()
        self.url = f"opc.tcp://127.0.0.1:{port}/"
        pw = "bench-secret"
        h = subprocess.run([REL / "motion-opcua", "--config", "/dev/null", "hash-password"],
                           input=pw.encode(), capture_output=True, check=True).stdout.decode().splitlines()[-1]
        demo = (ROOT / "deploy/demo.toml").read_text()
        demo = demo.replace('service_prefix = "motion"',
                            f'service_prefix = "{self.prefix}"\nstate_dir = "{self.dir}/state"\n'
                            f'runtime_dir = "{self.run}"')
        self.config = self.dir / "machine.toml"
        self.config.write_text(demo + EXTRA_AXIS + f'\n[opcua]\nendpoint = "{self.url}"\n'
                               f'[[opcua.user]]\nname = "op1"\npassword_hash = "{h}"\nrole = "operator"\n')
        self.pw = pw
        self.daemon = None
        self.opcua = None

    def start_daemon(self):
        env = dict(os.environ, MOTION_IO_BIN=str(REL / "motion-io"))
        self.daemon = subprocess.Popen([REL / "motion-supervisor", "run", "--config", self.config],
                                       env=env, stdout=subprocess.DEVNULL,
                                       stderr=open(self.dir / "daemon.err", "w"))
        wait(lambda: os.path.exists(f"{self.run}/{self.prefix}.session"), 30)
        time.sleep(2)

    def start_opcua(self):
        self.opcua = subprocess.Popen([REL / "motion-opcua", "--config", self.config],
                                      stdout=subprocess.DEVNULL,
                                      stderr=open(self.dir / "opcua.err", "a"))
        wait(lambda: "Now listening" in (self.dir / "opcua.err").read_text(), 60)

    def stop_opcua(self):
        self.opcua.send_signal(signal.SIGTERM)
        self.opcua.wait(30)
        # The next start appends to the same log: wait for a new line.
        (self.dir / "opcua.err").write_text("")

    def stats(self, reset):
        args = [REL / "motionctl", "--config", self.config, "stats", "--json"]
        args += ["--reset"] if reset else ["--since-reset"]
        return json.loads(subprocess.run(args, capture_output=True, check=True).stdout)

    def close(self):
        for p in (self.opcua, self.daemon):
            if p and p.poll() is None:
                p.send_signal(signal.SIGTERM)
                p.wait(30)


def free_port():
    import socket
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def wait(pred, timeout):
    until = time.time() + timeout
    while not pred():
        if time.time() > until:
            raise TimeoutError("waited too long")
        time.sleep(0.05)


class Args:
    pass


def ua_args(rig):
    a = Args()
    a.url, a.pki, a.name = rig.url, str(rig.dir / "client"), "client"
    return a


async def slice_off(rig, seconds):
    sup = mc.Supervisor(rig.prefix, rig.run)
    until = time.time() + seconds
    while time.time() < until:
        sup.request(REQ_HOME, ["I"])
        await asyncio.sleep(0.25)
        sup.request(REQ_UNHOME, ["I"])
        await asyncio.sleep(0.25)


async def slice_on(rig, seconds):
    a = ua_args(rig)
    async with await uac.client(a, user="op1", password=rig.pw) as c:
        ns, m = await uac.machine(c)
        axes = await m.get_child([f"{ns}:Axes"])
        nodes = []
        for ax in await axes.get_children():
            nodes += await ax.get_children(refs=ua.ObjectIds.HasComponent,
                                           nodeclassmask=ua.NodeClass.Variable)
        h = uac.Changes()
        sub = await c.create_subscription(100, h)
        await sub.subscribe_data_change(nodes, sampling_interval=100, queuesize=10)
        i = await axes.get_child([f"{ns}:I"])
        until = time.time() + seconds
        while time.time() < until:
            await i.call_method(f"{ns}:Home", ua.Variant(0.0, ua.VariantType.Double))
            await asyncio.sleep(0.25)
            await i.call_method(f"{ns}:Unhome")
            await asyncio.sleep(0.25)
        return len(nodes), len(h.values)


async def latency(rig, samples):
    a = ua_args(rig)
    sup = mc.Supervisor(rig.prefix, rig.run)
    triples, arrivals = [], []
    async with await uac.client(a) as c:
        ns, i = await uac.axis_node(c, "I")
        homed = await i.get_child([f"{ns}:HomedStatus"])
        h = uac.Changes()
        sub = await c.create_subscription(10, h)
        await sub.subscribe_data_change(homed, sampling_interval=0, queuesize=100)
        for _ in range(samples):
            sup.request(REQ_HOME, ["I"])
            await asyncio.sleep(0.15)
            n = len(h.values)
            t0 = time.time()
            r = sup.request(REQ_UNHOME, ["I"])
            t1 = time.time()
            ok = await uac.wait_for(lambda: any(v is False for _, v, _ in h.values[n:]), 2)
            if ok:
                t_n = next(t for t, v, _ in h.values[n:] if v is False)
                triples.append((t0, t1, r.cycle))
                arrivals.append(t_n)
            await asyncio.sleep(0.1)
    # The change happened in the cycle that applied the Unhome, between
    # sending it and its answer: latency from the window's middle, ± half
    # its width. (Not cycle × period: the cycle counter skips the periods
    # a late wake-up missed.)
    lat = sorted(t_n - (t0 + t1) / 2 for t_n, (t0, t1, _) in zip(arrivals, triples))
    half = sorted((t1 - t0) / 2 for t0, t1, _ in triples)
    return {"samples": len(lat), "p50_ms": round(lat[len(lat) // 2] * 1e3, 2),
            "p99_ms": round(lat[min(len(lat) - 1, int(len(lat) * 0.99))] * 1e3, 2),
            "max_ms": round(lat[-1] * 1e3, 2),
            "window_half_width_p50_ms": round(half[len(half) // 2] * 1e3, 2)}


def pick(s):
    lat = s["latency"]
    return {"wakeup_p99_us": lat["wakeup_us"]["p99"], "compute_p99_us": lat["compute_us"]["p99"],
            "wakeup_max_us": lat["wakeup_us"]["max"], "deadline_misses": lat["deadline_misses"],
            "cycles": lat["cycles"]}


async def main():
    p = argparse.ArgumentParser()
    p.add_argument("--slice", type=float, default=20.0)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--samples", type=int, default=150)
    a = p.parse_args()
    # Like the daemon's other clients: off the cycle's CPU (demo: cpu 1).
    os.sched_setaffinity(0, {c for c in os.sched_getaffinity(0) if c != 1} or {0})
    rig = Rig(a)
    out = {"slices": []}
    try:
        rig.start_daemon()
        rig.start_opcua()
        await uac.gen_cert(type("A", (), {"pki": str(rig.dir / "client"), "name": "client"}))
        subprocess.run([REL / "motion-opcua", "--config", rig.config, "trust",
                        rig.dir / "client/client.der"], check=True, capture_output=True)
        rig.stop_opcua()
        for _ in range(a.rounds):
            rig.stats(reset=True)
            await slice_off(rig, a.slice)
            out["slices"].append({"opcua": False, **pick(rig.stats(reset=False))})
            rig.start_opcua()
            rig.stats(reset=True)
            nodes, notes = await slice_on(rig, a.slice)
            out["slices"].append({"opcua": True, "monitored_items": nodes,
                                  "notifications": notes, **pick(rig.stats(reset=False))})
            rig.stop_opcua()
        rig.start_opcua()
        out["latency"] = await latency(rig, a.samples)
    finally:
        rig.close()
    for k in ("wakeup_p99_us", "compute_p99_us"):
        on = [s[k] for s in out["slices"] if s["opcua"]]
        off = [s[k] for s in out["slices"] if not s["opcua"]]
        out[f"{k}_ratio_on_off"] = round((sum(on) / len(on)) / (sum(off) / len(off)), 3)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    asyncio.run(main())
