"""Where a supervisor's session file is (needs no iceoryx2)."""

import os


def default_runtime_dir() -> str:
    """The supervisor's runtime directory by default (as motionctl's)."""
    return "/run/motion" if os.geteuid() == 0 else f"/tmp/motion-{os.geteuid()}"
