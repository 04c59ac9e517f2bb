"""The real instrument files of tests/data/instrument (SurfaceTopography's test data, MIT; see its README)."""

import lzma
import shutil
from pathlib import Path

FOLDER = Path(__file__).parent / "data" / "instrument"


def instrument_file(name, folder):
    """Copy the file ``name`` into ``folder`` (decompressing a stored ``name.xz``); returns its path."""
    target = Path(folder) / name
    packed = FOLDER / f"{name}.xz"
    if packed.is_file():
        with lzma.open(packed) as src, open(target, "wb") as dst:
            shutil.copyfileobj(src, dst)
    else:
        shutil.copyfile(FOLDER / name, target)
    return target
