"""The one progress protocol of the library: a callback ``progress(label, done, total)``.

``label`` (str) names the step under way; ``done`` of ``total`` steps are finished. The runner, the
sweeps, the studies and the reports call it; the command line draws it as a bar. A job of named
stages tells it through :class:`Progress`.
"""

from __future__ import annotations

__all__ = ["Progress", "stages_of", "each"]


class Progress:
    """The stages of a job, told to ``callback(label, done, total)``.

    Calling the object with a stage name reports its start (``done``: the stages before it);
    :meth:`note` reports something within the current stage (``"stage: text"``); :meth:`done`
    reports the end (``"done", total, total``). Without a callback nothing happens.
    """

    def __init__(self, stages, callback=None):
        self.stages, self.callback, self.current = list(stages), callback, None

    def __call__(self, stage):
        self.current = stage
        if self.callback is not None:
            self.callback(stage, self.stages.index(stage), len(self.stages))

    def note(self, text):
        if self.callback is not None:
            self.callback(f"{self.current}: {text}", self.stages.index(self.current), len(self.stages))

    def done(self):
        if self.callback is not None:
            self.callback("done", len(self.stages), len(self.stages))


def stages_of(progress, stages):
    """``progress`` itself when it is a :class:`Progress` (a caller's job holding these stages), else
    a :class:`Progress` of ``stages`` telling the callback ``progress`` (``None``: nobody)."""
    return progress if isinstance(progress, Progress) else Progress(stages, progress)


def each(items, progress, label):
    """Yield the ``items`` and tell ``progress`` (a callback or ``None``) ``label(item), k, n`` before
    the ``k``-th of ``n``, then ``"done", n, n``."""
    items = list(items)
    for k, item in enumerate(items):
        if progress is not None:
            progress(label(item), k, len(items))
        yield item
    if progress is not None:
        progress("done", len(items), len(items))
