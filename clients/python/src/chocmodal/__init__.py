"""Python client of chocmodal, the service for modal multi-contact dynamics of beam
bundles (OGC API – Processes): submit jobs and sweeps, follow them with a progress
bar, and read their results as Python objects and pandas DataFrames.

>>> import chocmodal                                                # doctest: +SKIP
>>> with chocmodal.Client("http://127.0.0.1:8080") as client:
...     job = client.submit("bundle-dynamics", inputs)
...     job.wait()                      # progress bar; QualityWarning unless verdict good
...     forces = job.history("contact_forces")      # DataFrame indexed by time (s)
...     contacts = job.contacts()                   # per-contact statistics
"""

from . import axes
from ._http import RetryPolicy
from ._version import __version__
from ._xarray import history_to_xarray
from .callbacks import SIGNATURE_HEADER, verify_signature
from .client import Client
from .errors import (
    ChocmodalConnectionError,
    ChocmodalError,
    FieldError,
    ProblemDocument,
    QualityWarning,
    TruncatedTableWarning,
)
from .jobs import Job
from .signals import Signal
from .sweeps import Sweep

__all__ = [
    "__version__",
    "Client",
    "Job",
    "Sweep",
    "Signal",
    "RetryPolicy",
    "ChocmodalError",
    "ChocmodalConnectionError",
    "ProblemDocument",
    "FieldError",
    "QualityWarning",
    "TruncatedTableWarning",
    "axes",
    "history_to_xarray",
    "verify_signature",
    "SIGNATURE_HEADER",
]
