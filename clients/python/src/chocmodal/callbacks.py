"""Receiving job callbacks: checking the ``Chocmodal-Signature`` header of a callback.

The service signs each callback POST with ``Chocmodal-Signature: t=<unix seconds>,
v1=<hex>``, where ``<hex>`` is the HMAC-SHA256 of the bytes ``<t>.<body>`` under a
secret of the job's tenant (one ``v1=`` per secret while a secret is being rotated).
A receiver accepts the body if one ``v1`` matches under a secret it knows and ``t`` is
recent (a replayed old delivery is refused).
"""

from __future__ import annotations

import hashlib
import hmac
import time
from typing import Iterable, Optional, Union

#: The header that carries the signature.
SIGNATURE_HEADER = "Chocmodal-Signature"


def verify_signature(
    header: Optional[str],
    body: bytes,
    secrets: Union[str, Iterable[str]],
    *,
    tolerance: float = 300.0,
    now: Optional[float] = None,
) -> bool:
    """Whether ``header`` (the ``Chocmodal-Signature`` value) signs ``body`` (the raw
    request bytes, before any JSON parsing) with one of ``secrets``, at most
    ``tolerance`` seconds from ``now`` (default: this machine's clock)."""
    if not header:
        return False
    timestamp: Optional[str] = None
    signatures: list[str] = []
    for part in header.split(","):
        name, _, value = part.strip().partition("=")
        if name == "t":
            timestamp = value
        elif name == "v1":
            signatures.append(value)
    if timestamp is None or not timestamp.isdigit() or not signatures:
        return False
    current = time.time() if now is None else now
    if abs(current - int(timestamp)) > tolerance:
        return False
    keys = [secrets] if isinstance(secrets, str) else list(secrets)
    signed = timestamp.encode() + b"." + body
    for key in keys:
        expected = hmac.new(key.encode(), signed, hashlib.sha256).hexdigest()
        if any(hmac.compare_digest(expected, given) for given in signatures):
            return True
    return False
