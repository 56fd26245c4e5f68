"""What can go wrong, as Python exceptions and warnings.

The service answers every error with an RFC 9457 problem document
(``application/problem+json``): ``type``, ``title``, ``status``, ``detail``, and for
refused inputs an ``errors`` list of ``{"pointer", "detail"}`` pointing into the request
body. :class:`ChocmodalError` carries that document; its text is the server's own
``detail`` followed by the rest of the document, never a bare status code.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Optional

__all__ = [
    "FieldError",
    "ProblemDocument",
    "ChocmodalError",
    "ChocmodalConnectionError",
    "QualityWarning",
]

PROBLEM_PREFIX = "https://chocmodal.dev/problems/"
OGC_PREFIX = "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/"


@dataclass(frozen=True)
class FieldError:
    """One refused field: a JSON pointer into the request body and why."""

    pointer: str
    detail: str


@dataclass(frozen=True)
class ProblemDocument:
    """An RFC 9457 problem document as the service sends it.

    ``extra`` keeps every member this class has no field for (``exceeded`` of a
    ``too-costly`` refusal, members a later server adds).
    """

    type: str
    title: str
    status: int
    detail: str
    errors: tuple[FieldError, ...] = ()
    extra: Mapping[str, Any] = field(default_factory=dict)

    @property
    def kind(self) -> str:
        """The last segment of ``type``: ``invalid-inputs``, ``job-failed``, ``server-busy``..."""
        return self.type.rstrip("/").rsplit("/", 1)[-1]

    @classmethod
    def from_json(cls, document: Mapping[str, Any], status: int) -> "ProblemDocument":
        """The problem of a parsed body; ``status`` (the response's) fills what it lacks."""
        errors = tuple(
            FieldError(str(e.get("pointer", "")), str(e.get("detail", "")))
            for e in document.get("errors") or ()
            if isinstance(e, Mapping)
        )
        known = {"type", "title", "status", "detail", "errors"}
        return cls(
            type=str(document.get("type", "about:blank")),
            title=str(document.get("title", "")),
            status=int(document.get("status", status) or status),
            detail=str(document.get("detail", "")),
            errors=errors,
            extra={k: v for k, v in document.items() if k not in known},
        )

    def to_json(self) -> dict[str, Any]:
        document: dict[str, Any] = {
            "type": self.type,
            "title": self.title,
            "status": self.status,
            "detail": self.detail,
        }
        if self.errors:
            document["errors"] = [{"pointer": e.pointer, "detail": e.detail} for e in self.errors]
        document.update(self.extra)
        return document


class ChocmodalError(Exception):
    """The service refused a request or a job failed: the server's problem document.

    ``str(error)`` starts with the server's ``detail``, then its status, title and type,
    and one line per refused field (``/inputs/beam/modes: must be between 1 and 78``).
    """

    problem: ProblemDocument

    def __init__(self, problem: ProblemDocument, *, method: Optional[str] = None, url: Optional[str] = None):
        self.problem = problem
        self.method = method
        self.url = url
        super().__init__(self._text())

    @property
    def status(self) -> int:
        return self.problem.status

    @property
    def type(self) -> str:
        return self.problem.type

    @property
    def kind(self) -> str:
        return self.problem.kind

    @property
    def detail(self) -> str:
        return self.problem.detail

    @property
    def errors(self) -> tuple[FieldError, ...]:
        return self.problem.errors

    def _text(self) -> str:
        p = self.problem
        lines = [p.detail or p.title or "the service answered with an error"]
        where = f" ({self.method} {self.url})" if self.method and self.url else ""
        lines.append(f"  {p.status} {p.title}: {p.type}{where}")
        for e in p.errors:
            lines.append(f"  {e.pointer}: {e.detail}")
        exceeded = p.extra.get("exceeded")
        if isinstance(exceeded, list):
            for item in exceeded:
                if isinstance(item, Mapping):
                    lines.append(
                        f"  exceeded: {item.get('quantity')} estimate {item.get('estimate')} > limit {item.get('limit')}"
                    )
        return "\n".join(lines)


class ChocmodalConnectionError(ConnectionError):
    """The service could not be reached (every retry included)."""


class QualityWarning(UserWarning):
    """A job succeeded but its results say they are not accurate enough.

    Raised with :func:`warnings.warn` when ``quality.verdict`` is not ``good``;
    ``verdict`` and ``reasons`` are the results' ``quality`` members.
    """

    def __init__(self, message: str, *, job_id: str = "", verdict: str = "", reasons: "tuple[str, ...]" = ()):
        super().__init__(message)
        self.job_id = job_id
        self.verdict = verdict
        self.reasons = tuple(reasons)

    @classmethod
    def of(cls, job_id: str, verdict: str, reasons: "list[str]") -> "QualityWarning":
        why = "; ".join(reasons) if reasons else "no reason given"
        return cls(f"job {job_id}: quality {verdict}: {why}", job_id=job_id, verdict=verdict, reasons=tuple(reasons))


class TruncatedTableWarning(UserWarning):
    """A per-impact table read whole holds fewer rows than the run had impacts.

    Past ``output.impacts.max_rows`` the service keeps the largest impacts by peak force,
    each contact's fair share first (docs/impacts.md); raised with :func:`warnings.warn`
    by :meth:`chocmodal.Job.impacts` with the run's ``impacts`` and the table's
    ``tabulated`` rows.
    """

    def __init__(self, message: str, *, job_id: str = "", impacts: int = 0, tabulated: int = 0):
        super().__init__(message)
        self.job_id = job_id
        self.impacts = impacts
        self.tabulated = tabulated
