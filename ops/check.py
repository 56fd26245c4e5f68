#!/usr/bin/env python3
"""Checks the monitoring files of ops/ against a live chocmodal server (CI: .ci/run).

1. Starts ``chocmodal serve`` (``$CHOCMODAL_BIN``, else ``target/debug/chocmodal``) on an
   ephemeral port with a fresh data directory capped at 1 MiB, runs one small job and
   uploads one signal too large for the cap (a refused write, 507), so that every
   metric family of docs/service.md's "Metrics" table has samples, and scrapes
   ``/metrics``.
2. Every query of the Grafana dashboard (panels and variables) and every expression of
   the Prometheus rules: each metric it names exists in the scrape, with every label it
   matches on, groups by or shows (legend, annotation), and every label value it
   compares with is in the scrape or in the docs' table.
3. The dashboard's structure: uid, title, panels each with a Prometheus data source and
   at least one query; the rules' annotations (summary, description, a runbook_url
   whose anchor exists in docs/service.md); prometheus.yml's rule files exist.
4. With promtool: the syntax of every dashboard query, and ``promtool check metrics`` on
   the scrape.

Standard library only. Without the binary or promtool the checks that need them are
skipped with the reason, except under ``CI=true``, where that is a failure.

    python3 ops/check.py            # from the repository root, or anywhere
"""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any, Iterator, Optional

REPO = Path(__file__).resolve().parents[1]
DASHBOARDS = REPO / "ops" / "grafana" / "dashboards"
PROVISIONING = REPO / "ops" / "grafana" / "provisioning"
PROMETHEUS = REPO / "ops" / "prometheus"
DOCS = REPO / "docs" / "service.md"
IN_CI = os.environ.get("CI", "").lower() == "true"

# Labels Prometheus attaches to every scraped series; `up` is Prometheus's own.
TARGET_LABELS = {"job", "instance"}
PROMETHEUS_SERIES = {"up": TARGET_LABELS}


class Failures:
    def __init__(self) -> None:
        self.messages: list[str] = []

    def __call__(self, where: str, message: str) -> None:
        self.messages.append(f"{where}: {message}")


# -- a YAML subset ---------------------------------------------------------------------
#
# Block mappings and sequences, plain, quoted and block (| >) scalars, one-line flow
# sequences and mappings of scalars: what the files of ops/ use. Anything else is an
# error, never a silent misreading.


class YamlError(ValueError):
    pass


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def _strip_comment(text: str) -> str:
    quote = None
    for i, c in enumerate(text):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or text[i - 1] in " \t"):
            return text[:i].rstrip()
    return text.rstrip()


def _split_flow(text: str) -> list[str]:
    items, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        elif c == "," and depth == 0:
            items.append(text[start:i].strip())
            start = i + 1
    last = text[start:].strip()
    if last:
        items.append(last)
    return items


def _key_split(text: str) -> Optional[tuple[str, str]]:
    """`key: rest` (key plain or quoted), or None when `text` is no mapping entry."""
    match = re.match(r"""^("(?:[^"\\]|\\.)*"|'(?:[^']|'')*'|[^\s"'#{}\[\],][^:#]*?)\s*:(?:\s+|$)(.*)$""", text)
    if not match:
        return None
    return _scalar(match.group(1)), match.group(2)


def _scalar(text: str) -> Any:
    text = _strip_comment(text).strip()
    if text.startswith('"'):
        if not text.endswith('"') or len(text) < 2:
            raise YamlError(f"unterminated string {text!r}")
        return json.loads(text)
    if text.startswith("'"):
        if not text.endswith("'") or len(text) < 2:
            raise YamlError(f"unterminated string {text!r}")
        return text[1:-1].replace("''", "'")
    if text.startswith("["):
        if not text.endswith("]"):
            raise YamlError(f"multi-line flow sequence {text!r}")
        return [_scalar(item) for item in _split_flow(text[1:-1])]
    if text.startswith("{"):
        if not text.endswith("}"):
            raise YamlError(f"multi-line flow mapping {text!r}")
        result = {}
        for item in _split_flow(text[1:-1]):
            pair = _key_split(item)
            if pair is None:
                raise YamlError(f"flow mapping item {item!r}")
            result[pair[0]] = _scalar(pair[1])
        return result
    if text in ("", "~", "null"):
        return None
    if text in ("true", "false"):
        return text == "true"
    if re.fullmatch(r"-?\d+", text):
        return int(text)
    if text[0] in "&*!|>%@`":
        raise YamlError(f"unsupported YAML {text!r}")
    return text


class _Yaml:
    def __init__(self, text: str):
        self.lines = text.split("\n")
        self.i = 0

    def _skip(self) -> None:
        while self.i < len(self.lines):
            stripped = self.lines[self.i].strip()
            if stripped and not stripped.startswith("#"):
                return
            self.i += 1

    def _line(self) -> Optional[str]:
        self._skip()
        return self.lines[self.i] if self.i < len(self.lines) else None

    def document(self) -> Any:
        line = self._line()
        if line is None:
            return None
        node = self._node(_indent(line))
        if self._line() is not None:
            raise YamlError(f"line {self.i + 1}: unexpected indentation")
        return node

    def _node(self, indent: int) -> Any:
        line = self._line()
        assert line is not None
        content = line.strip()
        if content == "-" or content.startswith("- "):
            return self._sequence(indent)
        if _key_split(content) is not None:
            return self._mapping(indent)
        raise YamlError(f"line {self.i + 1}: multi-line scalar {content!r}")

    def _sequence(self, indent: int) -> list:
        items = []
        while (line := self._line()) is not None and _indent(line) == indent:
            content = line.strip()
            if not (content == "-" or content.startswith("- ")):
                break
            rest = content[1:].lstrip()
            if not rest:
                self.i += 1
                nxt = self._line()
                items.append(self._node(_indent(nxt)) if nxt is not None and _indent(nxt) > indent else None)
            elif _key_split(rest) is not None:
                # "- key: value" opens a mapping whose keys sit where "key" does.
                column = indent + (len(content) - len(rest))
                self.lines[self.i] = " " * column + rest
                items.append(self._mapping(column))
            else:
                items.append(self._value(rest, indent))
        return items

    def _mapping(self, indent: int) -> dict:
        result: dict = {}
        while (line := self._line()) is not None and _indent(line) == indent:
            content = line.strip()
            pair = _key_split(content)
            if pair is None:
                break
            key, rest = pair
            if key in result:
                raise YamlError(f"line {self.i + 1}: duplicate key {key!r}")
            result[key] = self._value(rest, indent)
        if (line := self._line()) is not None and _indent(line) > indent:
            raise YamlError(f"line {self.i + 1}: unexpected indentation")
        return result

    def _value(self, rest: str, indent: int) -> Any:
        """The value after `key:` or `- ` on line self.i; leaves self.i after it."""
        rest = _strip_comment(rest)
        block = re.fullmatch(r"([|>])([+-]?)", rest)
        self.i += 1
        if block:
            return self._block_scalar(indent, block.group(1), block.group(2))
        if rest:
            return _scalar(rest)
        line = self._line()
        if line is None:
            return None
        if _indent(line) > indent:
            return self._node(_indent(line))
        if _indent(line) == indent and (line.strip() == "-" or line.strip().startswith("- ")):
            return self._sequence(indent)
        return None

    def _block_scalar(self, indent: int, style: str, chomp: str) -> str:
        body = []
        while self.i < len(self.lines):
            line = self.lines[self.i]
            if line.strip() and _indent(line) <= indent:
                break
            body.append(line)
            self.i += 1
        while body and not body[-1].strip():
            body.pop()
        if not body:
            return ""
        width = min(_indent(line) for line in body if line.strip())
        lines = [line[width:] for line in body]
        if style == "|":
            text = "\n".join(lines)
        else:
            text, blank = "", False
            for line in lines:
                if not line.strip():
                    text += "\n"
                    blank = True
                else:
                    text += line if (not text or blank) else " " + line
                    blank = False
        return text if chomp == "-" else text + "\n"


def load_yaml(path: Path) -> Any:
    try:
        return _Yaml(path.read_text()).document()
    except YamlError as error:
        raise YamlError(f"{path.relative_to(REPO)}: {error}") from None


# -- PromQL: the series a query reads -------------------------------------------------

AGGREGATORS = {
    "sum", "min", "max", "avg", "group", "stddev", "stdvar", "count", "count_values",
    "bottomk", "topk", "quantile", "limitk", "limit_ratio",
}
KEYWORDS = {"and", "or", "unless", "bool", "offset", "by", "without", "on", "ignoring",
            "group_left", "group_right", "atan2", "inf", "nan"}
GROUPING = {"by", "without", "on", "ignoring", "group_left", "group_right"}
TOKEN = re.compile(
    r"""\s*(?:
        (?P<string>"(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*'|`[^`]*`)
      | (?P<range>\[[^\]]*\])
      | (?P<number>0x[0-9a-fA-F]+|(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?(?:ms|[smhdwy])?(?:\d+(?:ms|[smhdwy]))*)
      | (?P<ident>[a-zA-Z_:][a-zA-Z0-9_:]*)
      | (?P<op>=~|!~|!=|==|<=|>=|[-+*/%^<>=(){},@])
    )""",
    re.VERBOSE,
)


class Selector:
    def __init__(self, metric: str, matchers: list[tuple[str, str, str]]):
        self.metric = metric
        self.matchers = matchers

    def __repr__(self) -> str:
        return f"{self.metric}{{{', '.join(f'{n}{o}{v!r}' for n, o, v in self.matchers)}}}"


class Query:
    """The selectors and the grouping labels (by, without, on, ignoring, group_*) of a
    PromQL expression."""

    def __init__(self, expr: str):
        self.expr = expr
        self.selectors: list[Selector] = []
        self.grouping: set[str] = set()
        self.by_lists: list[set[str]] = []
        tokens = []
        position = 0
        expr = expr.rstrip()
        while position < len(expr):
            match = TOKEN.match(expr, position)
            if not match or match.end() == position:
                raise ValueError(f"cannot read the query at {expr[position:position + 20]!r}")
            position = match.end()
            kind = match.lastgroup
            tokens.append((kind, match.group(kind)))
        i = 0
        while i < len(tokens):
            kind, text = tokens[i]
            following = tokens[i + 1] if i + 1 < len(tokens) else (None, None)
            if kind == "ident" and text.lower() in GROUPING:
                i += 1
                if following[1] == "(":
                    labels, i = self._label_list(tokens, i)
                    self.grouping |= labels
                    if text.lower() == "by":
                        self.by_lists.append(labels)
                continue
            if kind == "ident" and text.lower() == "offset":
                i += 2
                continue
            if kind == "ident" and (text.lower() in KEYWORDS or text in AGGREGATORS or following[1] == "("):
                i += 1
                continue
            if kind == "ident":
                matchers: list[tuple[str, str, str]] = []
                i += 1
                if following[1] == "{":
                    matchers, i = self._matchers(tokens, i)
                self.selectors.append(Selector(text, matchers))
                continue
            if kind == "op" and text == "{":
                raise ValueError("a selector without a metric name ({...}): name the metric")
            i += 1

    @staticmethod
    def _label_list(tokens: list, i: int) -> tuple[set[str], int]:
        labels = set()
        i += 1  # "("
        while i < len(tokens) and tokens[i][1] != ")":
            if tokens[i][0] == "ident":
                labels.add(tokens[i][1])
            i += 1
        return labels, i + 1

    @staticmethod
    def _matchers(tokens: list, i: int) -> tuple[list[tuple[str, str, str]], int]:
        matchers = []
        i += 1  # "{"
        while i < len(tokens) and tokens[i][1] != "}":
            if tokens[i][1] == ",":
                i += 1
                continue
            name, op, value = tokens[i], tokens[i + 1], tokens[i + 2]
            if name[0] != "ident" or op[1] not in ("=", "!=", "=~", "!~") or value[0] != "string":
                raise ValueError(f"cannot read the label matcher at {name[1]!r}")
            text = value[1]
            text = json.loads(text) if text.startswith('"') else text[1:-1]
            matchers.append((name[1], op[1], text))
            i += 3
        return matchers, i + 1


# -- Grafana's variables ----------------------------------------------------------------

VARIABLE = re.compile(r"\$\{(\w+)(?::\w+)?\}|\$(\w+)|\[\[(\w+)\]\]")
PLACEHOLDER = "__grafana_variable__"


def expand_grafana(expr: str) -> str:
    """A Grafana query as PromQL: time variables as a duration, others as a placeholder
    (label values that hold one are not checked)."""

    def replace(match: re.Match) -> str:
        name = match.group(1) or match.group(2) or match.group(3)
        if name.startswith("__") and name.endswith(("interval", "range")):
            return "5m"
        return PLACEHOLDER

    return VARIABLE.sub(replace, expr)


# -- the scrape and the docs ------------------------------------------------------------


class Scrape:
    """The series of a /metrics answer: per sample name, its label names and values."""

    def __init__(self, text: str):
        self.text = text
        self.families: dict[str, str] = {}  # family -> type
        self.labels: dict[str, dict[str, set[str]]] = {}  # sample name -> label -> values
        sample = re.compile(r"^([a-zA-Z_:][a-zA-Z0-9_:]*)(?:\{(.*)\})?\s+\S+(?:\s+\d+)?$")
        pair = re.compile(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"')
        for line in text.splitlines():
            if line.startswith("# TYPE "):
                _, _, name, kind = line.split(maxsplit=3)
                self.families[name] = kind
            elif line and not line.startswith("#"):
                match = sample.match(line)
                if not match:
                    raise ValueError(f"unreadable /metrics line {line!r}")
                labels = self.labels.setdefault(match.group(1), {})
                for name, value in pair.findall(match.group(2) or ""):
                    labels.setdefault(name, set()).add(value.replace('\\"', '"').replace("\\\\", "\\"))

    def family_of(self, sample_name: str) -> str:
        for suffix in ("_bucket", "_sum", "_count"):
            base = sample_name[: -len(suffix)]
            if sample_name.endswith(suffix) and self.families.get(base) in ("histogram", "summary"):
                return base
        return sample_name


def documented_metrics() -> dict[str, dict[str, set[str]]]:
    """docs/service.md's "Metrics" table: metric -> label -> documented values."""
    text = DOCS.read_text()
    if "\n## Metrics\n" not in text:
        return {}
    section = text.split("\n## Metrics\n", 1)[1].split("\n## ", 1)[0]
    metrics: dict[str, dict[str, set[str]]] = {}
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        match = re.fullmatch(r"`(chocmodal_\w+)`", cells[0]) if len(cells) >= 3 else None
        if not match:
            continue
        labels: dict[str, set[str]] = {}
        for label, values in re.findall(r"`(\w+)`(?:\s*\(([^)]*)\))?", cells[-1]):
            labels[label] = set(re.findall(r"`([^`]+)`", values))
        metrics[match.group(1)] = labels
    return metrics


def anchors(markdown: str) -> set[str]:
    """GitHub's anchors of the headings of a Markdown text."""
    found = set()
    markdown = re.sub(r"^```.*?^```", "", markdown, flags=re.M | re.S)  # code blocks
    for heading in re.findall(r"^#{1,6}\s+(.+?)\s*#*$", markdown, flags=re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", "")).replace(" ", "-")
        found.add(slug)
    return found


# -- the checks -------------------------------------------------------------------------


def check_query(
    where: str,
    expr: str,
    scrape: Optional[Scrape],
    docs: dict[str, dict[str, set[str]]],
    shown: set[str],
    fail: Failures,
) -> None:
    """The metrics and labels of `expr` exist; `shown` are the labels a legend or an
    annotation prints."""
    try:
        query = Query(expr)
    except ValueError as error:
        fail(where, f"{error} in {expr!r}")
        return
    if not query.selectors:
        fail(where, f"the query reads no metric: {expr!r}")
    available: set[str] = set(TARGET_LABELS)
    for selector in query.selectors:
        if selector.metric in PROMETHEUS_SERIES:
            labels = {name: set() for name in PROMETHEUS_SERIES[selector.metric]}
        elif scrape is None:
            family = selector.metric
            for suffix in ("_bucket", "_sum", "_count"):
                if family.endswith(suffix) and family[: -len(suffix)] in docs:
                    family = family[: -len(suffix)]
            if family not in docs:
                fail(where, f"metric {selector.metric} is not in docs/service.md's Metrics table")
                continue
            labels = {name: set() for name in docs[family]}
            if selector.metric.endswith("_bucket"):
                labels["le"] = set()
        elif selector.metric not in scrape.labels:
            fail(where, f"metric {selector.metric} is not in the server's /metrics (query {expr!r})")
            continue
        else:
            labels = scrape.labels[selector.metric]
        family = scrape.family_of(selector.metric) if scrape else selector.metric
        documented = docs.get(family, {})
        available |= set(labels)
        for name, op, value in selector.matchers:
            if name not in labels and name not in TARGET_LABELS:
                fail(where, f"{selector.metric} has no label {name!r} (it has {sorted(labels) or 'none'})")
                continue
            if PLACEHOLDER in value or scrape is None or name in TARGET_LABELS:
                continue
            if op in ("=", "!="):
                values = [value]
            elif re.fullmatch(r"[\w/{}-]+(\|[\w/{}-]+)*", value):
                values = value.split("|")  # a plain alternation: each one checked
            else:
                continue  # a pattern (5.., .*): not a list of values
            for one in values:
                if one not in labels[name] and one not in documented.get(name, set()):
                    fail(
                        where,
                        f"{selector.metric}{{{name}}} never takes the value {one!r} "
                        f"(seen: {sorted(labels[name])}; documented: {sorted(documented.get(name, set()))})",
                    )
    for name in sorted(query.grouping - available):
        fail(where, f"groups by {name!r}, a label none of its metrics has: {expr!r}")
    # What a legend or an annotation prints must survive the aggregations.
    kept = set.union(*query.by_lists) if query.by_lists else available
    for name in sorted(shown - kept):
        fail(where, f"shows label {name!r}, which its query does not keep (by {sorted(kept)}): {expr!r}")


def dashboard_queries(path: Path, fail: Failures) -> Iterator[tuple[str, str, set[str]]]:
    """Checks the structure of a dashboard; yields (where, PromQL, labels shown)."""
    name = path.relative_to(REPO)
    try:
        dashboard = json.loads(path.read_text())
    except ValueError as error:
        fail(str(name), f"not valid JSON: {error}")
        return
    for key in ("uid", "title"):
        if not isinstance(dashboard.get(key), str) or not dashboard[key].strip():
            fail(str(name), f"no {key}")
    variables = {v.get("name"): v for v in dashboard.get("templating", {}).get("list", [])}
    datasource_variables = {n for n, v in variables.items() if v.get("type") == "datasource" and v.get("query") == "prometheus"}
    provisioned = provisioned_datasources()

    def datasource_ok(where: str, datasource: Any) -> None:
        if not isinstance(datasource, dict) or datasource.get("type") != "prometheus":
            fail(where, f"data source {datasource!r} is not a Prometheus one ({{'type': 'prometheus', 'uid': ...}})")
            return
        uid = str(datasource.get("uid", ""))
        variable = VARIABLE.fullmatch(uid)
        if variable:
            if (variable.group(1) or variable.group(2) or variable.group(3)) not in datasource_variables:
                fail(where, f"data source {uid} is no Prometheus data source variable of the dashboard")
        elif uid not in provisioned:
            fail(where, f"data source uid {uid!r} is neither a variable nor provisioned ({sorted(provisioned)})")

    panels = list(dashboard.get("panels", []))
    for row in dashboard.get("panels", []):
        panels.extend(row.get("panels", []) if row.get("type") == "row" else [])
    if not [p for p in panels if p.get("type") != "row"]:
        fail(str(name), "no panels")
    ids = [p.get("id") for p in panels]
    for duplicate in sorted({i for i in ids if ids.count(i) > 1}, key=str):
        fail(str(name), f"panel id {duplicate} used twice")
    for panel in panels:
        if panel.get("type") == "row":
            continue
        where = f"{name}: panel {panel.get('title')!r}"
        if not panel.get("title"):
            fail(where, "no title")
        if not isinstance(panel.get("gridPos"), dict):
            fail(where, "no gridPos")
        datasource_ok(where, panel.get("datasource"))
        targets = panel.get("targets") or []
        if not targets:
            fail(where, "no query (targets)")
        refs = [t.get("refId") for t in targets]
        if len(set(refs)) != len(refs) or None in refs:
            fail(where, f"refIds missing or repeated: {refs}")
        for target in targets:
            there = f"{where} query {target.get('refId')}"
            if "datasource" in target:
                datasource_ok(there, target["datasource"])
            expr = target.get("expr", "")
            if not expr.strip():
                fail(there, "empty expr")
                continue
            legend = target.get("legendFormat", "")
            yield there, expand_grafana(expr), set(re.findall(r"\{\{\s*(\w+)\s*\}\}", legend))
    for variable in variables.values():
        if variable.get("type") != "query":
            continue
        where = f"{name}: variable {variable.get('name')!r}"
        datasource_ok(where, variable.get("datasource"))
        query = variable.get("query")
        query = query.get("query", "") if isinstance(query, dict) else str(query or "")
        match = re.fullmatch(r"\s*label_values\((.*),\s*(\w+)\s*\)\s*", query)
        if not match:
            fail(where, f"only label_values(<selector>, <label>) queries are checked, not {query!r}")
            continue
        yield where, expand_grafana(match.group(1)), {match.group(2)}


def provisioned_datasources() -> set[str]:
    uids = set()
    for path in sorted((PROVISIONING / "datasources").glob("*.y*ml")):
        for source in (load_yaml(path) or {}).get("datasources", []):
            uids.add(source.get("uid"))
    return uids


def rule_queries(path: Path, fail: Failures) -> Iterator[tuple[str, str, set[str]]]:
    """Checks the rules' annotations; yields (where, PromQL, labels shown)."""
    name = path.relative_to(REPO)
    text = path.read_text()
    document = load_yaml(path) or {}
    docs_text = DOCS.read_text()
    docs_anchors = anchors(docs_text)
    rules = [rule for group in document.get("groups", []) for rule in group.get("rules", [])]
    written = len(re.findall(r"^\s*- (?:alert|record):", text, flags=re.M))
    if len(rules) != written or not rules:
        fail(str(name), f"read {len(rules)} rules of the {written} written: this checker misread the file")
    for rule in rules:
        where = f"{name}: {rule.get('alert') or rule.get('record')}"
        annotations = rule.get("annotations") or {}
        shown: set[str] = set()
        if "alert" in rule:
            for key in ("summary", "description", "runbook_url"):
                if not str(annotations.get(key, "")).strip():
                    fail(where, f"no {key} annotation")
            if not (rule.get("labels") or {}).get("severity"):
                fail(where, "no severity label")
            runbook = str(annotations.get("runbook_url", ""))
            match = re.fullmatch(r"docs/service\.md#([\w-]+)", runbook)
            if not match or match.group(1) not in docs_anchors:
                fail(where, f"runbook_url {runbook!r} is no heading of docs/service.md")
            for value in list(annotations.values()) + list((rule.get("labels") or {}).values()):
                shown |= set(re.findall(r"\$labels\.(\w+)", str(value)))
        yield where, str(rule.get("expr", "")), shown


def check_prometheus_config(fail: Failures) -> list[Path]:
    config = load_yaml(PROMETHEUS / "prometheus.yml") or {}
    rule_files = []
    for entry in config.get("rule_files", []):
        path = PROMETHEUS / entry
        if not path.is_file():
            fail("ops/prometheus/prometheus.yml", f"rule file {entry} does not exist")
        else:
            rule_files.append(path)
    if not rule_files:
        fail("ops/prometheus/prometheus.yml", "no rule file")
    for job in config.get("scrape_configs", []):
        name = job.get("job_name", "")
        if name != "prometheus" and not name.startswith("chocmodal"):
            fail("ops/prometheus/prometheus.yml", f"job {name!r}: the alerts expect chocmodal-* job names")
    return rule_files


def promtool_syntax(promtool: str, queries: list[tuple[str, str]], fail: Failures) -> None:
    """promtool parses every query, as recording rules of a throwaway rule file (one
    file for all; one per query to name the culprit when that fails)."""

    def parses(batch: list[tuple[str, str]], directory: str) -> tuple[bool, str]:
        rules = Path(directory) / "queries.yml"
        rules.write_text(json.dumps({"groups": [{"name": "queries", "rules": [
            {"record": f"query_{index}", "expr": expr} for index, (_, expr) in enumerate(batch)]}]}))
        done = subprocess.run([promtool, "check", "rules", "--lint=none", str(rules)], capture_output=True, text=True)
        output = (done.stdout + done.stderr).strip().splitlines()
        return done.returncode == 0, " ".join(line.strip() for line in output if not line.startswith("Checking "))

    with tempfile.TemporaryDirectory(prefix="chocmodal-check-") as directory:
        if parses(queries, directory)[0]:
            return
        for where, expr in queries:
            ok, output = parses([(where, expr)], directory)
            if not ok:
                fail(where, f"promtool cannot parse {expr!r}: {output}")


# -- the server -------------------------------------------------------------------------


class Server:
    """One `chocmodal serve` (as clients/python/tests/conftest.py starts it)."""

    def __init__(self, binary: Path, directory: Path, *extra: str):
        self.log_path = directory / "server.log"
        self._log = open(self.log_path, "w")
        self.process = subprocess.Popen(
            [str(binary), "serve", "--bind", "127.0.0.1:0", "--data-dir", str(directory / "data"),
             "--workers", "1", "--log-format", "json", "--shutdown-grace-seconds", "1", *extra],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )
        found: dict[str, str] = {}
        ready = threading.Event()
        stderr = self.process.stderr
        assert stderr is not None

        def drain() -> None:
            for line in stderr:
                self._log.write(line)
                self._log.flush()
                if not ready.is_set() and "chocmodal is ready" in line:
                    try:
                        found["address"] = json.loads(line)["fields"]["address"]
                    except (ValueError, KeyError):
                        pass
                    ready.set()
            ready.set()

        self._drain = threading.Thread(target=drain, daemon=True)
        self._drain.start()
        if not ready.wait(60) or "address" not in found:
            self.stop()
            raise RuntimeError(f"chocmodal did not report ready in 60 s; its log:\n{self.log()}")
        self.url = f"http://{found['address']}"

    def log(self) -> str:
        return self.log_path.read_text()[-4000:]

    def request(self, method: str, path: str, body: bytes = b"", content_type: str = "application/json") -> tuple[int, dict, bytes]:
        request = urllib.request.Request(self.url + path, data=body or None, method=method,
                                         headers={"Content-Type": content_type} if body else {})
        try:
            with urllib.request.urlopen(request, timeout=60) as response:
                return response.status, dict(response.headers), response.read()
        except urllib.error.HTTPError as error:
            return error.code, dict(error.headers), error.read()

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=5)
        self._drain.join(timeout=5)
        if self.process.stderr is not None:
            self.process.stderr.close()
        self._log.close()


def exercise(server: Server) -> None:
    """One small job to its end, then one write the capped database refuses."""
    example = json.loads((REPO / "examples" / "cantilever-impact.json").read_text())
    example["inputs"]["solver"]["duration"] = 0.01
    status, headers, body = server.request("POST", "/processes/cantilever-impact/execution",
                                           json.dumps(example).encode())
    if status != 201:
        raise RuntimeError(f"the job was refused, {status}: {body[:500]!r}")
    location = headers.get("Location") or headers.get("location")
    deadline = time.monotonic() + 60
    while True:
        status, _, body = server.request("GET", location)
        job = json.loads(body)
        if job.get("status") not in ("accepted", "running"):
            break
        if time.monotonic() > deadline:
            raise RuntimeError(f"the job did not end in 60 s: {job}")
        time.sleep(0.05)
    if job.get("status") != "successful":
        raise RuntimeError(f"the job ended {job.get('status')}: {job}")
    # 200 000 random samples (over 1 MiB however compressed) into a 1 MiB database.
    rng = random.Random(34)
    signal = "\n".join(f"{rng.gauss(0.0, 1.0):.9e}" for _ in range(200_000)).encode()
    status, _, body = server.request("POST", "/signals?sampling_rate=100", signal, "text/csv")
    if status != 507:
        raise RuntimeError(f"the oversized signal was answered {status}, not 507: {body[:500]!r}")


def scrape_server(binary: Path) -> str:
    with tempfile.TemporaryDirectory(prefix="chocmodal-check-") as directory:
        server = Server(binary, Path(directory), "--max-database-mib", "1")
        try:
            exercise(server)
            status, _, body = server.request("GET", "/metrics")
            if status != 200:
                raise RuntimeError(f"/metrics answered {status}")
            return body.decode()
        except Exception:
            sys.stderr.write(f"server log:\n{server.log()}\n")
            raise
        finally:
            server.stop()


def find_binary() -> Optional[Path]:
    given = os.environ.get("CHOCMODAL_BIN")
    candidate = Path(given) if given else REPO / "target" / "debug" / "chocmodal"
    if not candidate.is_absolute():
        candidate = Path.cwd() / candidate
    return candidate if candidate.is_file() and os.access(candidate, os.X_OK) else None


def main() -> int:
    started = time.monotonic()
    fail = Failures()
    skipped: list[str] = []
    docs = documented_metrics()
    if not docs:
        fail("docs/service.md", "no Metrics table found")

    binary = find_binary()
    scrape: Optional[Scrape] = None
    if binary is None:
        skipped.append(
            f"no chocmodal binary at {os.environ.get('CHOCMODAL_BIN') or REPO / 'target/debug/chocmodal'} "
            "(cargo build, or set CHOCMODAL_BIN): queries checked against the docs' table only"
        )
    else:
        try:
            scrape = Scrape(scrape_server(binary))
        except (RuntimeError, OSError, ValueError) as error:
            fail("server", f"{error}")
            print(f"FAIL server: {error}")
            return 1
        print(f"scraped {len(scrape.families)} metric families from {binary} in {time.monotonic() - started:.1f} s", flush=True)
        for family in sorted(set(docs) - set(scrape.families)):
            fail("/metrics", f"{family} (docs/service.md) has no sample after a job and a refused write")
        for family in sorted(set(scrape.families) - set(docs)):
            fail("docs/service.md", f"{family} of /metrics is missing from the Metrics table")

    queries: list[tuple[str, str, set[str]]] = []
    for path in sorted(DASHBOARDS.glob("*.json")):
        queries.extend(dashboard_queries(path, fail))
    if not queries:
        fail("ops/grafana/dashboards", "no dashboard query")
    for path in check_prometheus_config(fail):
        queries.extend(rule_queries(path, fail))
    for where, expr, shown in queries:
        check_query(where, expr, scrape, docs, shown, fail)

    promtool = os.environ.get("PROMTOOL") or shutil.which("promtool")
    if promtool is None:
        skipped.append("no promtool (Debian: apt-get install prometheus): query syntax and /metrics lint not checked")
    else:
        promtool_syntax(promtool, [(where, expr) for where, expr, _ in queries], fail)
        if scrape is not None:
            done = subprocess.run([promtool, "check", "metrics"], input=scrape.text, capture_output=True, text=True)
            if done.returncode != 0 or done.stdout.strip():
                fail("/metrics", f"promtool check metrics: {(done.stdout + done.stderr).strip()}")

    for message in skipped:
        print(f"SKIPPED: {message}")
    for message in fail.messages:
        print(f"FAIL {message}")
    print(
        f"ops/check.py: {len(queries)} queries of the dashboard and the rules checked, "
        f"{len(fail.messages)} failures, {len(skipped)} skipped checks, {time.monotonic() - started:.1f} s"
    )
    if skipped and IN_CI:
        print("CI=true: a skipped check is a failure")
        return 1
    return 1 if fail.messages else 0


if __name__ == "__main__":
    sys.exit(main())
