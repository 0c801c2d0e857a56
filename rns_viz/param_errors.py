"""A parameter file's errors in its own words: msgspec's validation messages turned into
``[base] dampng: unknown key (did you mean damping?)``, with the element's path and the nearest known name."""

from __future__ import annotations

import difflib
import re
from typing import Any

import msgspec


def unknown(name: str, known: tuple[str, ...] | list[str], what: str) -> str:
    """``name`` is not one of ``known``: the nearest (did you mean ...?) or the list."""
    near = difflib.get_close_matches(name, list(known), n=1)
    hint = f"did you mean {near[0]}?" if near else f"one of {', '.join(known) or 'none'}"
    return f"unknown {what} {name!r} ({hint})"


# -- msgspec's errors in the file's words: "[base] dampng: unknown key (did you mean damping?)" ----------------

_ERROR = re.compile(r"^(?P<what>.*?)(?: - at `(?P<key>key)` in `(?P<dict>[^`]*)`| - at `(?P<at>[^`]*)`)?$", re.S)
_TYPE_WORDS = {
    "float": "a number",
    "int": "an integer",
    "str": "a string",
    "array": "a list",
    "object": "a table",
    "bool": "true or false",
    "null": "nothing",
}


def explain(message: str, data: dict[str, Any], schema: type) -> str:
    """A msgspec validation message as ``element: problem``, with the nearest known name for a misspelt one."""
    match = _ERROR.match(message)
    if match is None:
        return message
    what = match["what"]
    tokens = _tokens(match["dict"] or match["at"] or "$")
    target = _type_at(schema, tokens, data)
    if found := re.fullmatch(r"Object contains unknown field `(.+)`", what):
        key = found[1]
        fields = [f.encode_name for f in target.fields] if isinstance(target, msgspec.inspect.StructType) else []
        near = difflib.get_close_matches(key, fields, n=1) or [f for f in fields if f.startswith(key + "_")][:1]
        hint = f"did you mean {near[0]}?" if near else f"known: {', '.join(fields)}"
        if isinstance(_value_at([*tokens, key], data), dict):
            return f"[{'.'.join(map(str, (*tokens, key)))}]: unknown table ({hint})"
        return f"{element(schema, tokens, table=True)} {key}: unknown key ({hint})".lstrip()
    if found := re.fullmatch(r"Object missing required field `(.+)`", what):
        return f"{element(schema, tokens, table=True)} {found[1]}: missing".lstrip()
    if found := re.fullmatch(r"Invalid (?:enum )?value (.+)", what):
        choices = [str(c) for c in _choices(schema, target, tokens, data)]
        near = difflib.get_close_matches(found[1].strip("'"), choices, n=1)
        hint = f"did you mean {near[0]}?" if near else f"expected one of {', '.join(choices)}"
        return f"{element(schema, tokens)}: {found[1]} is not allowed ({hint})"
    return f"{element(schema, tokens)}: {_words(what)}"


def _words(what: str) -> str:
    """msgspec's ``Expected `float`, got `str``` as ``expected a number, got a string``."""

    def words(found: re.Match[str]) -> str:
        kinds = [k.strip() for k in found[1].split("|") if k.strip() != "null"]
        return " or ".join(_TYPE_WORDS.get(k, k) for k in kinds)

    text = re.sub(r"`([\w |]+)`", words, what)
    return text[:1].lower() + text[1:]


def _tokens(path: str) -> list[str | int]:
    """``$.base.stiffness[0][1]`` as ["base", "stiffness", 0, 1]."""
    return [int(t[1:-1]) if t.startswith("[") else t.lstrip(".") for t in re.findall(r"\.[^.\[]+|\[\d+\]", path)]


def element(schema: type, tokens: list[str | int], table: bool = False) -> str:
    """The element a path names, as a TOML reader writes it: ``[base] stiffness[0][1]``, ``[app.scene] base``
    (``table``: the path names a table, ``[app.scene.base]``)."""
    names: list[str] = []
    node: Any = msgspec.inspect.type_info(schema)
    rest = list(tokens)
    while rest and isinstance(rest[0], str):
        inner = _struct(_field(node, rest[0]))
        if inner is None or (len(rest) == 1 and not table):
            break
        names.append(str(rest.pop(0)))
        node = inner
    key = "".join(f"[{t}]" if isinstance(t, int) else ("." if i else "") + t for i, t in enumerate(rest))
    head = f"[{'.'.join(names)}]" if names else ""
    return f"{head} {key}".strip()


def _field(node: Any, name: str) -> Any:
    if isinstance(node, msgspec.inspect.StructType):
        return next((f.type for f in node.fields if f.encode_name == name), None)
    return None


def _struct(node: Any) -> Any:
    """The struct a field holds (an optional struct's too; the first of a tagged union)."""
    if isinstance(node, msgspec.inspect.StructType):
        return node
    if isinstance(node, msgspec.inspect.UnionType):
        return next((t for t in node.types if isinstance(t, msgspec.inspect.StructType)), None)
    return None


def _type_at(schema: type, tokens: list[str | int], data: dict[str, Any]) -> Any:
    """The type the schema expects at a path (optional unwrapped, a tagged union resolved by the kind written)."""
    node: Any = msgspec.inspect.type_info(schema)
    for i, token in enumerate(tokens):
        node = _field(node, token) if isinstance(token, str) else getattr(node, "item_type", None)
        if isinstance(node, msgspec.inspect.UnionType):
            structs = [t for t in node.types if isinstance(t, msgspec.inspect.StructType)]
            others = [t for t in node.types if not isinstance(t, msgspec.inspect.NoneType)]
            value = _value_at(tokens[: i + 1], data)
            kind = value.get(structs[0].tag_field) if structs and isinstance(value, dict) else None
            node = next((t for t in structs if t.tag == kind), structs[0] if structs else others[0])
    return node


def _choices(schema: type, node: Any, tokens: list[str | int], data: dict[str, Any]) -> list[object]:
    """The values a literal (or a tagged union's kind) allows."""
    if isinstance(node, msgspec.inspect.LiteralType):
        return list(node.values)
    if len(tokens) > 1 and tokens[-1] == "kind":  # a tagged union's tag: the struct holding the union
        union = _field(_type_at(schema, tokens[:-2], data), str(tokens[-2]))
        if isinstance(union, msgspec.inspect.UnionType):
            return [t.tag for t in union.types if isinstance(t, msgspec.inspect.StructType)]
    return []


def _value_at(tokens: list[str | int], data: Any) -> Any:
    for token in tokens:
        try:
            data = data[token]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def every_number(data: Any, tokens: tuple[str | int, ...] = ()) -> list[tuple[list[str | int], float]]:
    """Every float in the file with its path (for the finiteness check: TOML has nan and inf)."""
    if isinstance(data, float):
        return [(list(tokens), data)]
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    return [found for key, value in items for found in every_number(value, (*tokens, key))]


def kind_of(value: object) -> str:
    return _TYPE_WORDS.get(type(value).__name__, type(value).__name__)
