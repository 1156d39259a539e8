"""One run at a time writes a report folder (`run --out DIR`, `grade --out DIR`).

Two runs writing one folder would interleave their files and leave a
summary.json of one run beside the plots of the other. So a run locks the
folder for as long as it writes there: an exclusive ``flock`` on
``DIR/.fossbot-hil.lock`` (``harness.holder_lock``), in which the holder's
pid and command line are written for the message of a run that is
refused. The file is removed when the run lets go, so a finished folder
holds only the report; a killed run leaves it, unlocked, for the next run
to take over.
"""

from __future__ import annotations

from pathlib import Path

from harness.errors import ConfigError
from harness.holder_lock import Held, HolderLock, take

__all__ = ["LOCK_NAME", "lock_folder"]

LOCK_NAME = ".fossbot-hil.lock"


def lock_folder(folder: Path, label: str | Path) -> HolderLock:
    """This run's hold on `folder` (which must exist), until released or the process ends.

    ConfigError, one line starting with `label`, naming the run that holds it.
    """
    try:
        return take(folder / LOCK_NAME, remove=True)
    except Held as busy:
        raise ConfigError(
            f"{label}: in use by {busy.holder}: two runs writing one folder would mix their "
            "reports; wait for it to finish, or choose another folder"
        ) from None
    except OSError as err:
        raise ConfigError(f"{label}: cannot lock the folder: {err.strerror or err}") from None
