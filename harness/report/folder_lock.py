"""One run at a time writes a report folder (`run --out DIR`, `grade --out DIR`).

Two runs would leave a summary.json of one beside the plots of the other.
The lock (``harness.holder_lock``) names its holder for the refused run,
and is removed when the run lets go, so a finished folder holds only the
report; a killed run's lock, unlocked, is the next run's to take over.
"""

from __future__ import annotations

from pathlib import Path

from harness.errors import ConfigError
from harness.holder_lock import Held, HolderLock, take

__all__ = ["LOCK_NAME", "lock_folder"]

LOCK_NAME = ".fossbot-hil.lock"


def lock_folder(folder: Path, label: str | Path) -> HolderLock:
    """This run's hold on `folder` (which must exist); a ConfigError naming its holder."""
    try:
        return take(folder / LOCK_NAME, remove=True)
    except Held as busy:
        raise ConfigError(
            f"{label}: in use by {busy.holder}: two runs writing one folder would mix their "
            "reports; wait for it to finish, or choose another folder"
        ) from None
    except OSError as err:
        raise ConfigError(f"{label}: cannot lock the folder: {err.strerror or err}") from None
