"""What the report tests read of a written page: whether each of its tables sits in the sideways-scrolling element."""

from __future__ import annotations

from html.parser import HTMLParser

from workbench.apps.report import TABLE_SCROLL_CLASS

#: Elements without a closing tag.
VOID = frozenset({"meta", "img", "br", "hr", "link", "input", "source", "col", "wbr"})


class _Tables(HTMLParser):
    """For each table of the page, in order: whether the element it sits directly in is a div of
    TABLE_SCROLL_CLASS."""

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[tuple[str, set[str]]] = []
        self.scrolling: list[bool] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        classes = set((dict(attrs).get("class") or "").split())
        if tag == "table":
            parent = self.stack[-1] if self.stack else ("", set())
            self.scrolling.append(parent[0] == "div" and TABLE_SCROLL_CLASS in parent[1])
        if tag not in VOID:
            self.stack.append((tag, classes))

    def handle_endtag(self, tag: str) -> None:
        if tag in VOID:
            return
        while self.stack:  # close the innermost element of this tag (and any the page left open inside it)
            if self.stack.pop()[0] == tag:
                break


def tables_scrolling(page: str) -> list[bool]:
    """Whether each table of the page sits in the scrolling element (one entry per table, in order)."""
    parser = _Tables()
    parser.feed(page)
    parser.close()
    return parser.scrolling
