"""A Python client of motion-supervisor over iceoryx2 (the PyPI `iceoryx2`
package, 0.10.0): status, home, stop, unhome, enable, disable, reset, jog
(hold to run), move and the supervised setpoint stream.

    from motion_supervisor_client import Supervisor, accepted
    sup = Supervisor("motion")
    print(sup.status().axis_count)

`layout` (the ctypes classes, numbers and status properties, built from
the layout description the Rust side writes) and `check` (their
field-by-field comparison with that description) need only the standard
library; the client names below load iceoryx2 when first used.
"""

from .layout import *  # noqa: F401,F403  (the classes and numbers)

__version__ = "0.1.0"

_CLIENT = ("Supervisor", "NoSupervisor", "Jog", "SetpointStream", "accepted", "refusals", "default_runtime_dir")


def __getattr__(name):
    # The client imports iceoryx2: only when asked for (PEP 562), so the
    # layouts and their check work without it.
    if name in _CLIENT:
        from . import client

        return getattr(client, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
