"""Following something that runs on the server: the polling pace and the progress bar."""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator, Optional

from tqdm.std import tqdm

__all__ = ["Poller", "progress_bar", "Bar"]


class Poller:
    """The pace of status polls: fast at first (0.05 s, doubling), since small jobs end
    within a fraction of a second, then the server's ``Retry-After`` (at most 5 s), or
    a fixed ``interval`` when the caller gives one."""

    def __init__(self, interval: Optional[float] = None, *, first: float = 0.05, ceiling: float = 5.0):
        self.interval = interval
        self._next = first
        self.ceiling = ceiling

    def next_delay(self, retry_after: Optional[float]) -> float:
        if self.interval is not None:
            return self.interval
        limit = min(self.ceiling, retry_after if retry_after is not None else 1.0)
        delay = min(self._next, limit)
        self._next = min(self._next * 2, self.ceiling)
        return max(delay, 0.01)


class Bar:
    """A tqdm bar moved to absolute positions (the server reports where it is, not steps)."""

    def __init__(self, bar: Optional[Any]):
        self._bar = bar
        self._state: Optional[str] = None

    def show(self, position: float, state: str, *, total: Optional[float] = None) -> None:
        if self._bar is None:
            return
        if total is not None and total != self._bar.total:
            self._bar.total = total
        self._bar.n = position
        if state != self._state:
            self._bar.set_postfix_str(state, refresh=False)
            self._state = state
        self._bar.refresh()


@contextmanager
def progress_bar(enabled: bool, **options: Any) -> Iterator[Bar]:
    """A :class:`Bar` over a tqdm bar, or one that shows nothing when not ``enabled``."""
    if not enabled:
        yield Bar(None)
        return
    bar = tqdm(bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} [{elapsed}{postfix}]", **options)
    try:
        yield Bar(bar)
    finally:
        bar.close()
