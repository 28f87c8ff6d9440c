"""Where the PyPI package example-robot-data (a cmeel package) keeps its robots, for the CI checks."""
import os
import sys


def robots_dir():
    import cmeel  # noqa: F401  (example-robot-data is a cmeel package)
    for p in sys.path:
        d = os.path.join(p, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    sys.exit("example-robot-data not found")
