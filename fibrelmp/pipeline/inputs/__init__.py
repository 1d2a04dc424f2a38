"""The input hooks that have not moved to their format's home yet (MUSEN, .mdem, cmusen
scripts, CardioProof).  The hook base lives in ``fibrelmp.inputformat`` (core layer), where
a format home can derive from it; these names are re-exported for the hooks here."""

from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn, no_overrides

__all__ = ["InputFormat", "RunSettings", "Say", "Warn", "no_overrides"]
