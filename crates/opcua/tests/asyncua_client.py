#!/usr/bin/env python3
"""A real OPC UA client nobody here wrote (PyPI `asyncua`) against motion-opcua.

Run by crates/opcua/tests/e2e.rs, one scenario per run; prints one JSON
object on its last line and exits 0 when the scenario saw what it should.

    asyncua_client.py SCENARIO --url opc.tcp://127.0.0.1:PORT/ --pki DIR [options]
"""

import argparse
import asyncio
import json
import math
import os
import signal
import time
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.common.events import get_filter_from_event_type
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from cryptography.x509.oid import ExtendedKeyUsageOID

NS_URI = "urn:motion-supervisor"


def app_uri(name):
    return f"urn:motion-test:{name}"


async def gen_cert(a):
    os.makedirs(a.pki, exist_ok=True)
    key = Path(a.pki) / f"{a.name}.pem"
    cert = Path(a.pki) / f"{a.name}.der"
    await setup_self_signed_certificate(
        key, cert, app_uri(a.name), "localhost", [ExtendedKeyUsageOID.CLIENT_AUTH],
        {"countryName": "DE", "organizationName": "motion-test"})
    return {"cert": str(cert), "key": str(key)}


async def client(a, name=None, user=None, password=None):
    """A Basic256Sha256 Sign & Encrypt client with the certificate `name`."""
    name = name or a.name
    c = Client(a.url, timeout=10)
    c.application_uri = app_uri(name)
    await c.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=os.path.join(a.pki, f"{name}.der"),
        private_key=os.path.join(a.pki, f"{name}.pem"),
        mode=ua.MessageSecurityMode.SignAndEncrypt)
    if user:
        c.set_user(user)
        c.set_password(password)
    return c


async def machine(c):
    ns = await c.get_namespace_index(NS_URI)
    m = await c.nodes.objects.get_child([f"{ns}:Machine"])
    return ns, m


async def axis_node(c, axis):
    ns, m = await machine(c)
    return ns, await m.get_child([f"{ns}:Axes", f"{ns}:{axis}"])


def jsonable(v):
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    if isinstance(v, (bool, int, float, str)) or v is None:
        return v
    return str(v)


async def endpoints(a):
    c = Client(a.url, timeout=10)
    eps = await c.connect_and_get_server_endpoints()
    return {"endpoints": [[e.SecurityPolicyUri.split("#")[-1], e.SecurityMode.name,
                           [t.TokenType.name for t in e.UserIdentityTokens]] for e in eps]}


async def browse(a):
    """Anonymous: every axis's variables read, the I/O processes and latency."""
    async with await client(a) as c:
        ns, m = await machine(c)
        out = {"axes": {}, "io": {}, "latency": {}}
        axes = await m.get_child([f"{ns}:Axes"])
        for ax in await axes.get_children():
            name = (await ax.read_browse_name()).Name
            vals = {}
            for v in await ax.get_children(refs=ua.ObjectIds.HasComponent,
                                           nodeclassmask=ua.NodeClass.Variable):
                dv = await v.read_data_value(raise_on_bad_status=False)
                vals[(await v.read_browse_name()).Name] = {
                    "value": jsonable(dv.Value.Value), "status": dv.StatusCode.name}
            methods = [(await x.read_browse_name()).Name for x in
                       await ax.get_children(refs=ua.ObjectIds.HasComponent,
                                             nodeclassmask=ua.NodeClass.Method)]
            eu = await (await ax.get_child([f"{ns}:ActualPosition", "0:EngineeringUnits"])).read_value()
            vals["_eu"] = eu.DisplayName.Text
            vals["_methods"] = sorted(methods)
            out["axes"][name] = vals
        io = await m.get_child([f"{ns}:IO"])
        for p in await io.get_children():
            att = await p.get_child([f"{ns}:Attached"])
            out["io"][(await p.read_browse_name()).Name] = await att.read_value()
        lat = await m.get_child([f"{ns}:Latency"])
        for s in ("WakeUp", "Compute", "RoundTrip"):
            p99 = await lat.get_child([f"{ns}:{s}", f"{ns}:P99"])
            out["latency"][s] = jsonable((await p99.read_data_value(raise_on_bad_status=False)).Value.Value)
        return out


class Changes:
    def __init__(self):
        self.values = []
        self.events = []

    def datachange_notification(self, node, val, data):
        dv = data.monitored_item.Value
        self.values.append((time.time(), val, dv.SourceTimestamp.timestamp() if dv.SourceTimestamp else None))

    def event_notification(self, event):
        self.events.append(event.get_event_props_as_fields_dict())


async def wait_for(pred, timeout):
    until = time.time() + timeout
    while time.time() < until:
        if pred():
            return True
        await asyncio.sleep(0.02)
    return pred()


async def home(a):
    """Operator over Basic256Sha256 S&E: HomedStatus subscribed, Home called."""
    async with await client(a, user=a.user, password=a.password) as c:
        ns, ax = await axis_node(c, a.axis)
        homed = await ax.get_child([f"{ns}:HomedStatus"])
        h = Changes()
        sub = await c.create_subscription(10, h)
        await sub.subscribe_data_change(homed, queuesize=100, sampling_interval=10)
        await wait_for(lambda: h.values, 5)
        out = await ax.call_method(f"{ns}:Home", ua.Variant(0.0, ua.VariantType.Double))
        ok = await wait_for(lambda: any(v for _, v, _ in h.values), a.timeout)
        return {"outputs": [jsonable(x) for x in out], "homed": ok,
                "changes": [v for _, v, _ in h.values]}


async def er_event(a):
    """An axis that fails homing raises AxisErrorEventType with ERR/EXERR."""
    async with await client(a, user=a.user, password=a.password) as c:
        ns, ax = await axis_node(c, a.axis)
        etype = await c.nodes.base_event_type.get_child([f"{ns}:AxisErrorEventType"])
        h = Changes()
        sub = await c.create_subscription(10, h)
        # asyncua filters by InList on EventType, which async-opcua 0.19
        # never matches (it does not compare NodeIds in filters): OfType.
        flt = await get_filter_from_event_type([etype])
        flt.WhereClause = ua.ContentFilter(Elements=[ua.ContentFilterElement(
            FilterOperator=ua.FilterOperator.OfType,
            FilterOperands=[ua.LiteralOperand(Value=ua.Variant(etype.nodeid))])])
        await sub.subscribe_events(c.nodes.server, etype, evfilter=flt)
        await ax.call_method(f"{ns}:Home", ua.Variant(0.0, ua.VariantType.Double))
        ok = await wait_for(lambda: h.events, a.timeout)
        ev = h.events[0] if h.events else {}
        return {"event": bool(ok), "fields": {k: jsonable(getattr(v.Value, "Text", v.Value)) for k, v in ev.items()}}


async def expect_error(coro):
    try:
        await coro
    except Exception as e:  # noqa: BLE001 - the error's type is what we report
        return type(e).__name__
    return None


async def anon_call(a):
    """A method call by an anonymous session, or by `--login` (a viewer):
    Home, and the operations Jog and Enable."""
    async with await client(a, user=a.login, password=a.password) as c:
        ns, ax = await axis_node(c, a.axis)
        D = ua.VariantType.Double
        err = await expect_error(ax.call_method(f"{ns}:Home", ua.Variant(0.0, D)))
        jog = await expect_error(ax.call_method(f"{ns}:Jog", ua.Variant(5.0, D), ua.Variant(1.0, D)))
        enable = await expect_error(ax.call_method(f"{ns}:Enable"))
        return {"error": err, "jog": jog, "enable": enable}


async def read(ax, ns, name):
    dv = await (await ax.get_child([f"{ns}:{name}"])).read_data_value(raise_on_bad_status=False)
    return dv.Value.Value


async def poll(ax, ns, name, pred, timeout):
    """Reads `name` every 20 ms until `pred(value)`; the last value and whether it held."""
    until = time.time() + timeout
    v = await read(ax, ns, name)
    while not pred(v) and time.time() < until:
        await asyncio.sleep(0.02)
        v = await read(ax, ns, name)
    return v, pred(v)


async def enable_move(a):
    """Operator: Enable, then Move to `--target`; the position reaches it."""
    async with await client(a, user=a.user, password=a.password) as c:
        ns, ax = await axis_node(c, a.axis)
        enable = await ax.call_method(f"{ns}:Enable")
        _, servo = await poll(ax, ns, "ServoActionStatus", bool, 10)
        D = ua.VariantType.Double
        # Speed and the rest left out: the axis's defaults.
        out = await ax.call_method(f"{ns}:Move", ua.Variant(a.target, D),
                                   ua.Variant(False, ua.VariantType.Boolean))
        _, moving = await poll(ax, ns, "MoveStatus", bool, 5)
        pos, reached = await poll(ax, ns, "ActualPosition",
                                  lambda p: p is not None and abs(p - a.target) < 0.01, a.timeout)
        _, done = await poll(ax, ns, "MoveStatus", lambda m: not m, 5)
        # What the axis says, should it not have got there (a fault, lost
        # feedback on a loaded machine): the failure explains itself.
        why = {k: jsonable(await read(ax, ns, k)) for k in ("ER", "ERR", "EXERR", "Message")}
        return {"enable": [jsonable(x) for x in enable], "servo": servo,
                "outputs": [jsonable(x) for x in out], "moving_seen": moving or reached,
                "reached": reached and done, "position": jsonable(pos), "axis": why}


async def jog(a):
    """Operator: Jog at `--speed` with the lease `--duration` s, called once:
    it runs, then stops by itself while the session stays open (a frozen
    HMI). With `--close`: the session closes mid-jog instead and a second
    session sees it stop."""
    async with await client(a) as watcher:
        wns, wax = await axis_node(watcher, a.axis)
        start = await read(wax, wns, "ActualPosition")
        c = await client(a, user=a.user, password=a.password)
        await c.connect()
        ns, ax = await axis_node(c, a.axis)
        D = ua.VariantType.Double
        out = await ax.call_method(f"{ns}:Jog", ua.Variant(a.speed, D), ua.Variant(a.duration, D))
        _, seen = await poll(wax, wns, "JogStatus", bool, 5)
        t0 = time.time()
        if a.close:
            await c.disconnect()
        _, stopped = await poll(wax, wns, "JogStatus", lambda j: not j, a.timeout)
        took = time.time() - t0
        # The frozen caller's session is still there: the jog stopped anyway.
        session_open = None
        if not a.close:
            session_open = (await read(ax, ns, "JogStatus")) is not None
            await c.disconnect()
        end = await read(wax, wns, "ActualPosition")
        return {"outputs": [jsonable(x) for x in out], "jogging_seen": seen, "stopped": stopped,
                "took": took, "session_open": session_open,
                "moved": jsonable(end - start if end is not None and start is not None else None)}


async def jog_hold(a):
    """Operator: Jog at `--speed` with the lease `--duration`, called again
    every 0.2 s for `--hold` s (a button held): every call is accepted and
    the axis jogs throughout; then the calls stop and so does the axis.

    With `--config FILE --pid PID`: after a few calls the operator's role is
    taken away (FILE rewritten, SIGHUP to PID); the calls go on until one is
    refused, and the jog must stop."""
    async with await client(a) as watcher:
        wns, wax = await axis_node(watcher, a.axis)
        async with await client(a, user=a.user, password=a.password) as c:
            ns, ax = await axis_node(c, a.axis)
            D = ua.VariantType.Double
            call = lambda: ax.call_method(f"{ns}:Jog", ua.Variant(a.speed, D), ua.Variant(a.duration, D))
            outputs = [[jsonable(x) for x in await call()]]
            _, seen = await poll(wax, wns, "JogStatus", bool, 5)
            jogging, refused, calls = [], None, 1
            until = time.time() + a.hold
            while time.time() < until:
                await asyncio.sleep(0.2)
                if a.config and calls == 3:
                    text = Path(a.config).read_text()
                    Path(a.config).write_text(text.replace('role = "operator"', 'role = "viewer"'))
                    os.kill(a.pid, signal.SIGHUP)
                refused = await expect_error(call())
                calls += 1
                if refused is not None:
                    break
                jogging.append(bool(await read(wax, wns, "JogStatus")))
            _, stopped = await poll(wax, wns, "JogStatus", lambda j: not j, a.timeout)
        return {"first": outputs[0], "jogging_seen": seen, "calls": calls, "refused": refused,
                "jogging_throughout": all(jogging), "polls": len(jogging), "stopped": stopped}


async def none_call(a):
    """Over the None endpoint (when configured): reads work, calls do not."""
    c = Client(a.url, timeout=10)
    async with c:
        ns, ax = await axis_node(c, a.axis)
        homed = await (await ax.get_child([f"{ns}:HomedStatus"])).read_value()
        err = await expect_error(ax.call_method(f"{ns}:Home", ua.Variant(0.0, ua.VariantType.Double)))
        return {"read": homed, "error": err}


async def wrong_password(a):
    c = await client(a, user=a.user, password=a.password + "x")
    return {"error": await expect_error(c.connect())}


async def untrusted(a):
    c = await client(a, name=a.other)
    return {"error": await expect_error(c.connect())}


async def fuzz(a):
    """Hostile method arguments: every one refused with a Bad status, none crashes."""
    results = {}
    async with await client(a, user=a.user, password=a.password) as c:
        ns, m = await machine(c)
        ax = await m.get_child([f"{ns}:Axes", f"{ns}:{a.axis}"])
        D, S, B = ua.VariantType.Double, ua.VariantType.String, ua.VariantType.Boolean
        cases = {
            "nan": (ax, "Home", [ua.Variant(float("nan"), D)]),
            "inf": (ax, "Home", [ua.Variant(float("inf"), D)]),
            "huge": (ax, "Home", [ua.Variant(1e308, D)]),
            "negative": (ax, "Home", [ua.Variant(-1.0, D)]),
            "string_for_double": (ax, "Home", [ua.Variant("5", S)]),
            "missing": (ax, "Home", []),
            "too_many": (ax, "Stop", [ua.Variant(1.0, D)]),
            "unknown_axis": (m, "HomeAll", [ua.Variant(["NoSuchAxis"], S), ua.Variant(False, B),
                                            ua.Variant(0.0, D)]),
            "long_name": (m, "HomeAll", [ua.Variant(["x" * 300], S), ua.Variant(False, B),
                                         ua.Variant(0.0, D)]),
            "nul_name": (m, "HomeAll", [ua.Variant(["X\0"], S), ua.Variant(False, B),
                                        ua.Variant(0.0, D)]),
            "int_for_bool": (m, "HomeAll", [ua.Variant([], S), ua.Variant(1, ua.VariantType.Int32),
                                            ua.Variant(0.0, D)]),
            "jog_nan_speed": (ax, "Jog", [ua.Variant(float("nan"), D), ua.Variant(1.0, D)]),
            "jog_huge_speed": (ax, "Jog", [ua.Variant(1e308, D), ua.Variant(1.0, D)]),
            "jog_inf_duration": (ax, "Jog", [ua.Variant(1.0, D), ua.Variant(float("inf"), D)]),
            "jog_long_duration": (ax, "Jog", [ua.Variant(1.0, D), ua.Variant(1e9, D)]),
            # Hold to run: a lease over a second is not one.
            "jog_ten_seconds": (ax, "Jog", [ua.Variant(1.0, D), ua.Variant(10.0, D)]),
            "jog_zero_duration": (ax, "Jog", [ua.Variant(1.0, D), ua.Variant(0.0, D)]),
            "jog_missing": (ax, "Jog", [ua.Variant(1.0, D)]),
            "move_nan": (ax, "Move", [ua.Variant(float("nan"), D), ua.Variant(False, B),
                                      ua.Variant(0.0, D)]),
            "move_huge": (ax, "Move", [ua.Variant(1e308, D), ua.Variant(False, B),
                                       ua.Variant(0.0, D)]),
            "move_nan_speed": (ax, "Move", [ua.Variant(1.0, D), ua.Variant(False, B),
                                            ua.Variant(float("nan"), D)]),
            "move_too_many": (ax, "Move", [ua.Variant(1.0, D), ua.Variant(False, B)]
                              + [ua.Variant(1.0, D)] * 5),
            "move_string": (ax, "Move", [ua.Variant("1", S), ua.Variant(False, B),
                                         ua.Variant(0.0, D)]),
            "enable_too_many": (ax, "Enable", [ua.Variant(1.0, D)]),
        }
        for name, (obj, meth, args) in cases.items():
            results[name] = await expect_error(obj.call_method(f"{ns}:{meth}", *args))
        # Still serving: a read after all of it.
        results["after"] = await (await m.get_child([f"{ns}:Connected"])).read_value()
    return results


async def connected(a):
    """Waits until Machine.Connected reads `--want` (reconnects too)."""
    until = time.time() + a.timeout
    last = None
    while time.time() < until:
        try:
            async with await client(a) as c:
                ns, m = await machine(c)
                node = await m.get_child([f"{ns}:Connected"])
                while time.time() < until:
                    dv = await node.read_data_value(raise_on_bad_status=False)
                    last = dv.Value.Value
                    if last == (a.want == "true"):
                        return {"connected": last}
                    await asyncio.sleep(0.1)
        except Exception as e:  # noqa: BLE001 - motion-opcua may be restarting
            last = type(e).__name__
            await asyncio.sleep(0.3)
    return {"connected": last, "timeout": True}


async def latency(a):
    """Status change in the cycle → data-change notification here, s
    (arrival − source timestamp) for ActualPosition of a moving axis."""
    async with await client(a) as c:
        ns, ax = await axis_node(c, a.axis)
        pos = await ax.get_child([f"{ns}:ActualPosition"])
        h = Changes()
        sub = await c.create_subscription(10, h)
        await sub.subscribe_data_change(pos, queuesize=1000, sampling_interval=0)
        await asyncio.sleep(a.timeout)
        lat = sorted(t - s for t, _, s in h.values[1:] if s)
        return {"n": len(lat), "p50": lat[len(lat) // 2] if lat else None,
                "p99": lat[int(len(lat) * 0.99)] if lat else None}


SCENARIOS = {f.__name__.replace("_", "-"): f for f in
             (gen_cert, endpoints, browse, home, er_event, anon_call, none_call, wrong_password,
              untrusted, fuzz, connected, latency, enable_move, jog, jog_hold)}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scenario", choices=sorted(SCENARIOS))
    p.add_argument("--url", default="")
    p.add_argument("--pki", required=True)
    p.add_argument("--name", default="client")
    p.add_argument("--other", default="stranger")
    p.add_argument("--user", default="op1")
    p.add_argument("--login", default=None)
    p.add_argument("--password", default="")
    p.add_argument("--axis", default="X")
    p.add_argument("--want", default="true")
    p.add_argument("--timeout", type=float, default=30.0)
    p.add_argument("--target", type=float, default=10.0)
    p.add_argument("--speed", type=float, default=5.0)
    p.add_argument("--duration", type=float, default=1.0)
    p.add_argument("--close", action="store_true")
    p.add_argument("--hold", type=float, default=2.0)
    p.add_argument("--config", default=None)
    p.add_argument("--pid", type=int, default=0)
    a = p.parse_args()
    out = asyncio.run(SCENARIOS[a.scenario](a))
    print(json.dumps(out))


if __name__ == "__main__":
    main()
