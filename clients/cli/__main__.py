"""``python -m cnc_objects.clients.cli`` is ``cnc``."""

from . import main

main()
