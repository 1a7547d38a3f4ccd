"""A tokenizer and recursive-descent parser for OpenSCAD's ``.csg`` files.

``openscad model.scad -o model.csg`` writes the evaluated CSG tree: module
instantiations with named arguments, children in braces::

    difference() {
        cube(size = [10, 10, 10], center = false);
        multmatrix([[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, 1, -1], [0, 0, 0, 1]]) {
            cylinder($fn = 24, $fa = 12, $fs = 2, h = 12, r1 = 3, r2 = 3, center = false);
        }
    }

Values are numbers, strings, ``true``/``false``/``undef`` and nested
vectors. Nothing is evaluated: no expressions, variables or functions are
accepted. Every error is a :class:`OpenSCADError` with the line and column.

Examples
--------
>>> tree = parse('cube(size = [1, 2, 3], center = true);')
>>> tree[0].name, tree[0].args["size"], tree[0].args["center"]
('cube', [1.0, 2.0, 3.0], True)
>>> parse('cube(size = 1)')
Traceback (most recent call last):
...
csg.openscad_parser.OpenSCADError: <csg>:1:15: expected ';' or '{' after cube(...), got end of file
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Optional

__all__ = ["OpenSCADError", "Node", "parse", "tokenize", "unescape", "MAX_DEPTH", "MAX_TOKENS"]

#: nesting depth limit (modules and vectors); the parser recurses, so this stays well
#: inside Python's recursion limit
MAX_DEPTH = 200
#: token limit (a 100 MB file); larger input is refused
MAX_TOKENS = 20_000_000



_ESCAPE = re.compile(r"\\(?:x([0-7][0-9a-fA-F])|u([0-9a-fA-F]{4})|U([0-9a-fA-F]{6})|(.))",
                     re.DOTALL)
_SIMPLE_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", '"': '"', "\\": "\\"}


def unescape(body: str) -> str:
    """A string literal's text (without its quotes) with OpenSCAD's escapes
    (``\\n \\t \\r \\" \\\\``, ``\\xHH`` up to 7F, ``\\uHHHH``, ``\\UHHHHHH``) decoded;
    any other character, non-ASCII too, stands for itself.

    >>> unescape(r'a\\"b\\u263C') == 'a"b\u263c'
    True
    """
    def one(m: re.Match) -> str:
        code = m.group(1) or m.group(2) or m.group(3)
        if code is not None:
            return chr(min(int(code, 16), 0x10FFFF))
        return _SIMPLE_ESCAPES.get(m.group(4), m.group(0))
    return _ESCAPE.sub(one, body)


class OpenSCADError(ValueError):
    """Malformed or unsupported ``.csg`` input, with its location (``column`` is
    ``None`` where the source names none: OpenSCAD's own errors on a ``.scad``
    file give a line only)."""

    def __init__(self, message: str, line: int, column: Optional[int],
                 source: str = "<csg>"):
        self.line, self.column, self.source = line, column, source
        where = f"{source}:{line}" if column is None else f"{source}:{line}:{column}"
        super().__init__(f"{where}: {message}")


class OpenSCADWarning(UserWarning):
    """Degenerate ``.csg`` input that OpenSCAD skips (a zero-size cube, a singular
    transform, ...): the reader skips it too and names it, with its location."""


@dataclass
class Token:
    kind: str        # "ident", "number", "string", "punct", "eof"
    text: str
    line: int
    column: int


@dataclass
class Node:
    """A module instantiation: ``name(args) { children }``."""

    name: str
    args: dict[str, Any]
    positional: list[Any]
    children: list["Node"] = field(default_factory=list)
    line: int = 0
    column: int = 0
    #: OpenSCAD's modifier characters before the name: ``%`` background, ``#``
    #: highlight, ``*`` disable, ``!`` root
    modifiers: str = ""


_TOKEN = re.compile(r"""
    (?P<space>[ \t\r]+) | (?P<newline>\n) |
    (?P<comment>//[^\n]*|/\*.*?\*/) |
    (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?) |
    (?P<ident>\$?[A-Za-z_][A-Za-z0-9_]*) |
    (?P<string>"(?:[^"\\\n]|\\.)*") |
    (?P<punct>[()\[\]{},;=\-+]) |
    (?P<modifier>[%#*!])
""", re.VERBOSE | re.DOTALL)


def tokenize(text: str, source: str = "<csg>") -> list[Token]:
    """Split ``text`` into tokens; an unknown character is an error at its position."""
    tokens: list[Token] = []
    pos, line, line_start = 0, 1, 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        col = pos - line_start + 1
        if m is None:
            ch = text[pos]
            if ch == '"':
                raise OpenSCADError("unterminated string", line, col, source)
            if text.startswith("/*", pos):
                raise OpenSCADError("unterminated comment", line, col, source)
            raise OpenSCADError(f"unexpected character {ch!r}", line, col, source)
        kind = m.lastgroup
        chunk = m.group()
        if kind == "newline":
            line, line_start = line + 1, m.end()
        elif kind == "comment":
            newlines = chunk.count("\n")
            if newlines:
                line += newlines
                line_start = pos + chunk.rfind("\n") + 1
        elif kind != "space":
            tokens.append(Token(kind, chunk, line, col))
            if len(tokens) > MAX_TOKENS:
                raise OpenSCADError(f"input too large (over {MAX_TOKENS} tokens)", line, col,
                                    source)
        pos = m.end()
    tokens.append(Token("eof", "", line, pos - line_start + 1))
    return tokens


class _Parser:
    def __init__(self, tokens: list[Token], source: str):
        self.tokens, self.i, self.source = tokens, 0, source

    @property
    def tok(self) -> Token:
        return self.tokens[self.i]

    def error(self, message: str, tok: Optional[Token] = None) -> OpenSCADError:
        t = tok or self.tok
        return OpenSCADError(message, t.line, t.column, self.source)

    def describe(self, tok: Token) -> str:
        return "end of file" if tok.kind == "eof" else repr(tok.text)

    def expect(self, text: str, what: str) -> Token:
        if self.tok.text != text or self.tok.kind not in ("punct",):
            raise self.error(f"expected {text!r} {what}, got {self.describe(self.tok)}")
        t = self.tok
        self.i += 1
        return t

    def statements(self, depth: int, closing: Optional[Token]) -> list[Node]:
        out = []
        while True:
            t = self.tok
            if t.kind == "eof":
                if closing is not None:
                    raise self.error(f"'{{' at line {closing.line}, column {closing.column} "
                                     "is never closed")
                return out
            if t.kind == "punct" and t.text == "}":
                if closing is None:
                    raise self.error("unbalanced '}' (no '{' to close)")
                self.i += 1
                return out
            if t.kind == "punct" and t.text == ";":
                self.i += 1                         # an empty statement
                continue
            out.append(self.statement(depth))

    def statement(self, depth: int) -> Node:
        if depth > MAX_DEPTH:
            raise self.error(f"nesting deeper than {MAX_DEPTH} levels")
        modifiers = ""
        while self.tok.kind == "modifier":
            modifiers += self.tok.text
            self.i += 1
        t = self.tok
        if t.kind != "ident":
            raise self.error(f"expected a module name, got {self.describe(t)}")
        self.i += 1
        self.expect("(", f"after module name {t.text!r}")
        args, positional = self.arguments(depth)
        node = Node(t.text, args, positional, line=t.line, column=t.column, modifiers=modifiers)
        nxt = self.tok
        if nxt.kind == "punct" and nxt.text == ";":
            self.i += 1
        elif nxt.kind == "punct" and nxt.text == "{":
            self.i += 1
            node.children = self.statements(depth + 1, nxt)
        elif nxt.kind in ("ident", "modifier"):        # a single child without braces
            node.children = [self.statement(depth + 1)]
        else:
            raise self.error(f"expected ';' or '{{' after {t.text}(...), got "
                             f"{self.describe(nxt)}")
        return node

    def arguments(self, depth: int) -> tuple[dict[str, Any], list[Any]]:
        args: dict[str, Any] = {}
        positional: list[Any] = []
        if self.tok.kind == "punct" and self.tok.text == ")":
            self.i += 1
            return args, positional
        while True:
            t = self.tok
            if t.kind == "ident" and self.tokens[self.i + 1].text == "=" and \
                    t.text not in ("true", "false", "undef"):
                self.i += 2
                if t.text in args:
                    raise self.error(f"argument {t.text!r} given twice", t)
                args[t.text] = self.value(depth)
            else:
                if args:
                    raise self.error("positional argument after named ones")
                positional.append(self.value(depth))
            t = self.tok
            if t.kind == "punct" and t.text == ",":
                self.i += 1
                continue
            if t.kind == "punct" and t.text == ")":
                self.i += 1
                return args, positional
            raise self.error(f"expected ',' or ')' in the arguments, got {self.describe(t)}")

    def value(self, depth: int) -> Any:
        if depth > MAX_DEPTH:
            raise self.error(f"nesting deeper than {MAX_DEPTH} levels")
        t = self.tok
        if t.kind == "punct" and t.text in "-+" and self.tokens[self.i + 1].kind == "number":
            self.i += 2
            v = float(self.tokens[self.i - 1].text)
            return -v if t.text == "-" else v
        if t.kind == "number":
            self.i += 1
            return float(t.text)
        if t.kind == "string":
            self.i += 1
            return unescape(t.text[1:-1])
        if t.kind == "ident" and t.text in ("true", "false", "undef", "inf", "nan"):
            self.i += 1
            return {"true": True, "false": False, "undef": None,
                    "inf": float("inf"), "nan": float("nan")}[t.text]
        if t.kind == "punct" and t.text == "[":
            self.i += 1
            items = []
            if self.tok.kind == "punct" and self.tok.text == "]":
                self.i += 1
                return items
            while True:
                items.append(self.value(depth + 1))
                t2 = self.tok
                if t2.kind == "punct" and t2.text == ",":
                    self.i += 1
                    continue
                if t2.kind == "punct" and t2.text == "]":
                    self.i += 1
                    return items
                raise self.error(f"expected ',' or ']' in a vector, got {self.describe(t2)}")
        raise self.error(f"expected a value (number, string, true, false, undef or vector), "
                         f"got {self.describe(t)}")


def parse(text: str, source: str = "<csg>") -> list[Node]:
    """Parse ``.csg`` text to its top-level nodes."""
    if not isinstance(text, str):
        raise TypeError(f"text must be str, got {type(text).__name__}")
    parser = _Parser(tokenize(text, source), source)
    try:
        return parser.statements(0, None)
    except RecursionError:     # a deep stack beneath us: refuse rather than crash
        t = parser.tok
        raise OpenSCADError("nesting too deep for the parser", t.line, t.column, source) \
            from None
