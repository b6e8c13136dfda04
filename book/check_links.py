#!/usr/bin/env python3
"""Check the internal links of the built book.

Run after `mdbook build book`:

    python3 book/check_links.py [book/book]

Every relative `href`/`src` in the generated chapter pages must name a file
that exists in the output, and every `#fragment` an `id` in the target page.
External links (with a scheme) and site-absolute paths are not followed.

It also checks the book's sources (`book/src`, beside the output): every
`{{#include FILE}}` or `{{#include FILE:ANCHOR}}` must name a file that
exists and, with an anchor, a file that holds both `ANCHOR: ANCHOR` and
`ANCHOR_END: ANCHOR` (mdbook includes nothing, silently, for a missing
anchor). Exits 1 on any broken link or include.
"""
import html.parser
import pathlib
import re
import sys
import urllib.parse

INCLUDE = re.compile(r"\{\{#(?:include|rustdoc_include)\s+([^}\s]+)\s*\}\}")


def broken_includes(src):
    """Broken `{{#include}}`s of the markdown files under `src`."""
    broken = 0
    for md in sorted(src.rglob("*.md")):
        for m in INCLUDE.finditer(md.read_text(encoding="utf-8")):
            target, _, anchor = m.group(1).partition(":")
            path = (md.parent / target).resolve()
            if not path.is_file():
                print(f"{md.relative_to(src)}: include of a missing file {target}")
                broken += 1
                continue
            # `file:N:M` (line ranges) are not anchors.
            if anchor and not anchor[0].isdigit():
                text = path.read_text(encoding="utf-8")
                ends = re.search(rf"ANCHOR_END:\s*{re.escape(anchor)}\b", text)
                if not re.search(rf"ANCHOR:\s*{re.escape(anchor)}\b", text) or not ends:
                    print(f"{md.relative_to(src)}: no anchor {anchor!r} in {target}")
                    broken += 1
    return broken


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name == "id" and value:
                self.ids.add(value)
            if name in ("href", "src") and value is not None:
                self.links.append(value)


def parse(path):
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "book/book").resolve()
    if not (root / "index.html").is_file():
        sys.exit(f"{root}: no index.html; run `mdbook build book` first")
    pages = {p: parse(p) for p in root.rglob("*.html")}
    broken = 0
    for path, page in sorted(pages.items()):
        for link in page.links:
            url = urllib.parse.urlsplit(link)
            if url.scheme or url.netloc or link.startswith(("mailto:", "javascript:")):
                continue
            if url.path.startswith("/"):
                continue  # site-absolute (the 404 page's links): depends on site-url
            target = (path.parent / urllib.parse.unquote(url.path)).resolve() if url.path else path
            if target.is_dir():
                target = target / "index.html"
            if not target.is_file():
                print(f"{path.relative_to(root)}: missing target {link}")
                broken += 1
                continue
            frag = urllib.parse.unquote(url.fragment)
            if frag and target.suffix == ".html":
                ids = pages[target].ids if target in pages else parse(target).ids
                if frag not in ids:
                    print(f"{path.relative_to(root)}: no id {frag!r} in {link}")
                    broken += 1
    src = root.parent / "src"
    includes = broken_includes(src) if src.is_dir() else 0
    print(
        f"{len(pages)} pages, {sum(len(p.links) for p in pages.values())} links, {broken} broken; "
        f"{includes} broken includes"
    )
    sys.exit(1 if broken or includes else 0)


if __name__ == "__main__":
    main()
