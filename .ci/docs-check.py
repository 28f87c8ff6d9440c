#!/usr/bin/env python3
"""Every internal link of the built user guide resolves: each href/src in docs/book/**/*.html that points
inside the book names a file that exists, and its #fragment an id in that file. Usage: docs-check.py BOOK_DIR"""
import html.parser
import pathlib
import sys
import urllib.parse

book = pathlib.Path(sys.argv[1]).resolve()


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.links = set(), []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("id", "name") and value:
                self.ids.add(value)
            if name in ("href", "src") and value:
                self.links.append(value)


pages = {}
for path in book.rglob("*.html"):
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    pages[path] = page

broken = []
checked = 0
for path, page in pages.items():
    # 404.html links to the site's root, which only a web server gives it
    if path.name == "404.html":
        continue
    for link in page.links:
        url = urllib.parse.urlsplit(link)
        if url.scheme or url.netloc or link.startswith("mailto:") or link.startswith("javascript:"):
            continue
        target = path if not url.path else (path.parent / urllib.parse.unquote(url.path)).resolve()
        if target.is_dir():
            target = target / "index.html"
        checked += 1
        if not str(target).startswith(str(book)) or not target.exists():
            broken.append(f"{path.relative_to(book)}: {link}: no such file")
            continue
        if url.fragment and target.suffix == ".html":
            ids = pages[target].ids if target in pages else set()
            if urllib.parse.unquote(url.fragment) not in ids:
                broken.append(f"{path.relative_to(book)}: {link}: no id '{url.fragment}' in {target.relative_to(book)}")

if not pages:
    sys.exit(f"docs-check: no HTML pages under {book}")
for line in broken:
    print("docs-check: broken link:", line, file=sys.stderr)
print(f"docs-check: {len(pages)} pages, {checked} internal links, {len(broken)} broken")
sys.exit(1 if broken else 0)
