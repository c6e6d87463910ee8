"""Fail the build when the built site does not read offline, or one of its links leads nowhere.

Once the HTML is written (and after the other extensions' ``build-finished`` handlers, which copy files such as the
local MathJax into ``_static``), every page of the output is read, and each of these is a warning, which ``-W`` turns
into a failed build:

- a script, stylesheet, icon, image, font or frame loaded from another host (an ``src`` or a resource ``href`` with a
  scheme or starting ``//``): MathJax from a CDN, say, which a reader without a network never gets;
- a local file that a page loads or links to and the build does not have;
- a link within the site to an anchor (``page.html#name``, or ``#name`` on the page itself) that the target page
  does not define.

Links to other sites (an ``<a href>`` with a scheme, a ``mailto:``) are followed by the reader, not loaded, and are
not checked (the build is offline).
"""

from __future__ import annotations

import html.parser
import pathlib
import posixpath
from dataclasses import dataclass, field
from urllib.parse import unquote, urlsplit

# <link rel=...> values whose href the browser loads with the page (the rest are navigation: prev, next, index ...)
LOADED_RELS = {"stylesheet", "icon", "shortcut", "apple-touch-icon", "preload", "modulepreload", "prefetch",
               "manifest", "mask-icon"}
# (tag, attribute) pairs whose URL the browser loads with the page
LOADED_ATTRS = {("script", "src"), ("img", "src"), ("iframe", "src"), ("source", "src"), ("video", "src"),
                ("audio", "src"), ("embed", "src"), ("object", "data"), ("video", "poster")}


@dataclass
class Page:
    """What one HTML page defines and refers to."""

    ids: set[str] = field(default_factory=set)  # every id= and name= of its elements (the anchors it defines)
    loads: list[str] = field(default_factory=list)  # URLs the browser loads with the page
    links: list[str] = field(default_factory=list)  # URLs of its links (<a href>, navigation <link>s)


class _Scanner(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.page = Page()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        for name in ("id", "name"):
            if attrs.get(name) and (name == "id" or tag == "a"):
                self.page.ids.add(attrs[name])
        for (loaded_tag, attr) in LOADED_ATTRS:
            if tag == loaded_tag and attrs.get(attr):
                self.page.loads.append(attrs[attr])
        if tag == "link" and attrs.get("href"):
            rels = set((attrs.get("rel") or "").lower().split())
            (self.page.loads if rels & LOADED_RELS else self.page.links).append(attrs["href"])
        if tag == "a" and attrs.get("href"):
            self.page.links.append(attrs["href"])


def scan(text: str) -> Page:
    """The anchors, loaded URLs and links of the HTML page ``text``."""
    scanner = _Scanner()
    scanner.feed(text)
    scanner.close()
    return scanner.page


def is_remote(url: str) -> bool:
    """Whether ``url`` points at another host (``https://...``, ``//host/...``) rather than into the site."""
    return bool(urlsplit(url).scheme) or url.startswith("//")


def problems(outdir: str | pathlib.Path) -> list[str]:
    """Every remote load, missing local file and missing anchor of the HTML pages under ``outdir``, one line each
    (``page: what``), in page order."""
    outdir = pathlib.Path(outdir)
    pages = {p.relative_to(outdir).as_posix(): scan(p.read_text(encoding="utf-8"))
             for p in sorted(outdir.rglob("*.html"))}
    found = []
    for name, page in pages.items():
        for url in page.loads:
            if urlsplit(url).scheme == "data":
                continue
            if is_remote(url):
                found.append(f"{name}: loads {url} from another host (the site must read offline)")
            else:
                found += _local_target(outdir, pages, name, url, loaded=True)
        for url in page.links:
            if not is_remote(url):
                found += _local_target(outdir, pages, name, url, loaded=False)
    return found


def _local_target(outdir, pages, name, url, loaded):
    """The problem (at most one) with the site-relative ``url`` that page ``name`` loads or links to."""
    parts = urlsplit(url)
    path = unquote(parts.path)
    target = posixpath.normpath(posixpath.join(posixpath.dirname(name), path)) if path else name
    if target.startswith("../"):
        return [f"{name}: {url} points outside the site"]
    if not (outdir / target).exists():
        return [f"{name}: {'loads' if loaded else 'links to'} {url}, which the build does not have"]
    if (outdir / target).is_dir():
        target = posixpath.join(target, "index.html")
    anchor = unquote(parts.fragment)
    if anchor and target in pages and anchor not in pages[target].ids:
        return [f"{name}: links to {url}, but {target} has no anchor {anchor!r}"]
    return []


def check(app, exception):
    from sphinx.util import logging  # here, so that the tests import this module without Sphinx

    if exception is not None or app.builder.format != "html":
        return
    logger = logging.getLogger(__name__)
    for problem in problems(app.outdir):
        logger.warning(problem, type="site_check")


def setup(app):
    app.connect("build-finished", check, priority=900)  # after the handlers that copy files into the output
    return {"parallel_read_safe": True, "parallel_write_safe": True}
