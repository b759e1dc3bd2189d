"""The tests import meshcast from PYTHONPATH (the build's python/ folder:
PYTHONPATH=build/python python3 -m pytest python/tests) and their own helper
modules (oracle.py, shapes.py, cases.py) from this folder."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
