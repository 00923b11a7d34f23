"""The clumpforge Python module for the bench scripts: from PYTHONPATH, else the build tree's
build/python. Their track readings are the library's, not copied into the scripts."""
import pathlib
import sys


def library():
    try:
        import clumpforge
    except ImportError:
        sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "build" / "python"))
        import clumpforge
    return clumpforge
