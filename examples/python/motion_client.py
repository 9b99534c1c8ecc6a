#!/usr/bin/env python3
"""The `motion-client` command of the Python client package, as a script.

    pip install ./python            # from the repository (pulls iceoryx2==0.10.0)
    python3 examples/python/motion_client.py --prefix motion --home X

Everything is in the package `motion_supervisor_client` (python/): the
ctypes layouts checked field by field against the Rust types, the client
(status, home, stop, unhome, enable, disable, reset, jog, move, stream) and
this command's flags (`motion-client --help`).
"""

import sys

from motion_supervisor_client.cli import main

if __name__ == "__main__":
    sys.exit(main())
