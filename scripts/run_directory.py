"""The directory a results script runs its simulations in: the one `--out` names (kept), else
a temporary one, removed when the script ends (a table's runs write about 1 GB of traces)
unless `--keep` is given."""

import contextlib
import sys
import tempfile
from pathlib import Path


def add_arguments(ap) -> None:
    """`--out DIR` and `--keep` on the script's argument parser."""
    ap.add_argument("--out", type=Path, default=None, help="run in DIR and keep the runs there")
    ap.add_argument("--keep", action="store_true",
                    help="keep the temporary directory of the runs (its path printed on stderr)")


@contextlib.contextmanager
def run_directory(out: Path | None, keep: bool, prefix: str):
    """`out` (created), or a temporary directory named with `prefix`, removed on leaving the
    block (on an error too) unless `keep`."""
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        yield out
    elif keep:
        path = Path(tempfile.mkdtemp(prefix=prefix))
        print(f"runs kept in {path}", file=sys.stderr)
        yield path
    else:
        with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
            yield Path(tmp)
