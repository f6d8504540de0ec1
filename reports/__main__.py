"""``python -m reports`` runs the ``microcyl`` command line."""
import sys

from reports.cli import main

sys.exit(main())
