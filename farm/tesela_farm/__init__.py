"""tesela-farm: Tesela renders on a Dask cluster (see the README's "Render farms")."""

from .farm import FarmError, Settings, connect, render_each, render_still

__all__ = ["FarmError", "Settings", "connect", "render_each", "render_still"]
