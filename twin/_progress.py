"""One progress-bar helper for every long loop (tqdm, or a silent stand-in)."""
from __future__ import annotations


class _Silent:
    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


def progress_bar(total: int, enabled: bool, desc: str, unit: str = "it"):
    """A tqdm bar with ``update(n)``/``close()``, or a silent object with the same methods."""
    if not enabled:
        return _Silent()
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit=unit, unit_scale=unit == "samples", leave=False)
