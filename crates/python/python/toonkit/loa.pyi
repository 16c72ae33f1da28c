"""Dynamic lines of action (SBIM 2015) (type stubs)."""

from typing import Any, Callable, Iterable, Mapping, Optional, Union

from ._native import Line as Line

def line(
    keystrokes: Iterable[Mapping[str, Any]],
    mode: str = "physics",
    fps: float = 24.0,
    elements: int = 10,
    substeps: int = 8,
    simulated_frames: Union[int, str] = 40,
    progress: Optional[Callable[[str, float], Any]] = None,
) -> Line: ...
