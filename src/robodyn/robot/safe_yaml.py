"""One safe YAML reader for every YAML file robodyn reads (descriptions, recording specs, study
files, joint maps): safe constructors only, aliases and nesting deeper than
:data:`MAX_YAML_DEPTH` refused from the event stream, duplicate keys refused, the size bounded,
and every error naming the file and the line.
"""

from __future__ import annotations

from typing import Any

import yaml

from robodyn.robot.errors import DescriptionError

__all__ = ["MAX_YAML_CHARS", "MAX_YAML_DEPTH", "parse_yaml", "safe_yaml"]

#: Deepest nesting of YAML collections accepted (a description needs about 8 levels).
MAX_YAML_DEPTH = 32


class _Refused(yaml.MarkedYAMLError):
    """Valid YAML that a robot description does not accept (an alias, too deep a nesting)."""

    def __init__(self, problem: str, mark: yaml.Mark) -> None:
        super().__init__(problem=problem, problem_mark=mark)


class _UniqueKeys:
    """Constructor mix-in: a key repeated in one mapping is an error, not a silent overwrite."""

    def construct_mapping(self, node: yaml.Node, deep: bool = False) -> dict[Any, Any]:
        if isinstance(node, yaml.MappingNode):
            seen: set[Any] = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=deep)  # type: ignore[attr-defined]
                try:
                    duplicate = key in seen
                except TypeError:
                    continue  # unhashable: the base class reports it
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        "while constructing a mapping", node.start_mark,
                        f"found duplicate key {key!r}", key_node.start_mark,
                    )
                seen.add(key)
        return super().construct_mapping(node, deep=deep)  # type: ignore[misc]


def _alias_refused(event: yaml.AliasEvent) -> _Refused:
    return _Refused(
        f"YAML alias *{event.anchor} is not allowed in robot descriptions or any YAML robodyn "
        "reads (aliases can expand a small file to gigabytes); write the values out",
        event.start_mark,
    )


def _too_deep(event: yaml.Event) -> _Refused:
    return _Refused(f"nested more than {MAX_YAML_DEPTH} levels deep", event.start_mark)


class _UniqueKeyLoader(_UniqueKeys, yaml.SafeLoader):
    """``yaml.SafeLoader`` that rejects aliases and a key repeated in one mapping.

    Aliases (``*name``) are refused where they occur: a few hundred bytes of nested aliases
    expand to gigabytes once the data is copied, printed or hashed ("billion laughs"), and a
    robot description has no need of them.
    """

    _depth = 0

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node | None:
        if self.check_event(yaml.AliasEvent):
            raise _alias_refused(self.peek_event())
        if self._depth >= MAX_YAML_DEPTH:
            raise _too_deep(self.peek_event())
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


#: libyaml's parser and composer (PyYAML built with it), 10-20x faster than the pure-Python ones
_CSafeLoader = getattr(yaml, "CSafeLoader", None)


if _CSafeLoader is not None:
    class _CUniqueKeyLoader(_UniqueKeys, _CSafeLoader):  # type: ignore[misc, valid-type]
        """libyaml's loader with the duplicate-key check (aliases and depth: :func:`_c_events_checked`)."""


def _c_events_checked(text: str) -> None:
    """Refuse aliases and nesting deeper than :data:`MAX_YAML_DEPTH` from libyaml's flat event
    stream, before its (recursive) composer builds anything, as :class:`_UniqueKeyLoader` does."""
    depth = 0
    for event in yaml.parse(text, Loader=_CSafeLoader):
        if isinstance(event, yaml.AliasEvent):
            raise _alias_refused(event)
        if isinstance(event, yaml.NodeEvent) and depth >= MAX_YAML_DEPTH:
            raise _too_deep(event)
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


#: Largest YAML text read for a spec, study or mapping (characters): a hand-written file is a few
#: kilobytes; a bigger one is refused before parsing.
MAX_YAML_CHARS = 4 * 2**20


def safe_yaml(text: str, source: str, error: type[Exception]) -> Any:
    """YAML text -> Python data as robot descriptions are read, for every YAML robodyn reads
    (recording specs, study files, joint mappings): safe constructors only, aliases and nesting
    deeper than :data:`MAX_YAML_DEPTH` refused from the event stream, a key repeated in one
    mapping refused, at most :data:`MAX_YAML_CHARS` characters. Problems raise ``error`` with
    ``source`` and the line."""
    if len(text) > MAX_YAML_CHARS:
        raise error(f"{source}: {len(text)} characters of YAML; at most {MAX_YAML_CHARS} are read "
                    "(a hand-written file is a few kilobytes)")
    try:
        return parse_yaml(text, source)
    except DescriptionError as exc:
        raise error(str(exc)) from None


def parse_yaml(text: str, source: str) -> Any:
    """YAML text -> Python data (safe constructors only), errors with file and line."""
    try:
        if _CSafeLoader is not None and _utf8(text):
            try:
                _c_events_checked(text)
                return yaml.load(text, Loader=_CUniqueKeyLoader)  # noqa: S506 - CSafeLoader's
            except yaml.YAMLError:
                pass  # refused or invalid: the pure-Python loader says why, in its own words
        return yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown line"
        problem = exc.problem or exc.context or "invalid YAML"
        kind = "" if isinstance(exc, _Refused) else "YAML syntax error: "
        raise DescriptionError(f"{source}: {where}: {kind}{problem}") from None
    except yaml.YAMLError as exc:
        raise DescriptionError(f"{source}: YAML syntax error: {exc}") from None


def _utf8(text: str) -> bool:
    """Whether libyaml can take ``text`` (it encodes to UTF-8; lone surrogates cannot be, and the
    pure-Python reader then names the character)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True
