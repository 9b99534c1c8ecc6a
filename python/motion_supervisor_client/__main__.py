"""`python -m motion_supervisor_client`: the `motion-client` command."""

import sys

from .cli import main

sys.exit(main())
