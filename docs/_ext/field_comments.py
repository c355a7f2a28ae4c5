"""The comment at the end of each field's line of a dataclass, the doc the reference lists beside a field that has
no option doc (docs/conf.py). Standard library only: tests/docs/test_field_docs.py reads the fields through this
same function without Sphinx, so that the test and the reference agree on what documents a field."""

from __future__ import annotations

import inspect
import io
import re
import textwrap
import tokenize

#: A comment that only instructs a tool (a type checker, a linter, a formatter) documents nothing.
TOOL_PRAGMA = re.compile(r"^(type:|noqa|fmt:|pragma\b)")


def trailing_comments(cls: type) -> dict[str, str]:
    """The comment at the end of each ``name: type = value  # comment`` line of the class body, by field name.

    Only a line of the class body itself counts (indented once): a comment on a line of its own, on a method's
    line or on a continuation line documents nothing, nor does a tool's pragma (``# type: ignore[...]``). Empty
    when the source cannot be read.
    """
    try:
        source = textwrap.dedent(inspect.getsource(cls))
    except (OSError, TypeError):
        return {}
    comments: dict[str, str] = {}
    lines = source.splitlines()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type != tokenize.COMMENT:
            continue
        line = lines[token.start[0] - 1]
        head = line[: token.start[1]].strip()
        if ":" in head and not head.startswith(("def ", "class ", "#")) and line.startswith("    ") and \
                not line.startswith("        "):
            name = head.split(":", 1)[0].strip()
            text = token.string.lstrip("#:").strip()
            if name.isidentifier() and not TOOL_PRAGMA.match(text):
                comments[name] = text
    return comments
