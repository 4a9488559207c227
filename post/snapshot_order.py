"""The order of the snapshots in a dem2d snapshots.h5.

/snapshots names each snapshot by its index, written with at least six digits (000000, 000001,
..., 999999, 1000000, ...), so sorting the names as text puts 1000000 before 999999. The
scripts order them by the number instead:

    snapshot_key(name)       sort key: the name's trailing number, then the name
    snapshot_names(f)        the names under /snapshots of an open h5py file, in index order
"""

import re

_TRAILING_NUMBER = re.compile(r"(\d+)$")


def snapshot_key(name):
    """Sort key of a snapshot's name: its trailing number (names without one sort last)."""
    match = _TRAILING_NUMBER.search(name)
    return (0, int(match.group(1)), name) if match else (1, 0, name)


def snapshot_names(f):
    """The names of the snapshots under /snapshots of an open h5py file, in index order."""
    return sorted(f["snapshots"].keys(), key=snapshot_key) if "snapshots" in f else []
