"""What a page must not hold: markup that came from data (shared by the HTML tests)."""

from html.parser import HTMLParser
from pathlib import Path

from hypothesis import strategies as st

#: What a hostile file holds in every text and number field.
P = "<script>alert(1)</script>"
#: More payloads: an attribute break-out, a link scheme, an entity that must stay text.
PAYLOADS = [P, '"><img src=x onerror=alert(1)>', "javascript:alert(1)", "' onmouseover='x",
            "&lt;script&gt;", "</section><script>alert(2)</script>"]
#: The tags microcyl writes; anything else on a page came from data.
TAGS = {"html", "head", "meta", "title", "style", "body", "nav", "h1", "h2", "h3", "p", "a",
        "b", "i", "small", "code", "sub", "section", "figure", "figcaption", "img", "table",
        "thead", "tbody", "tr", "th", "td", "ul", "li", "div", "span", "footer", "br",
        "link", "main", "header", "article", "dl", "dt", "dd",
        "script"}


class Inert(HTMLParser):
    """Collects what a page would run: foreign tags, on* attributes, script links."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.bad, self.texts, self.in_script = [], [], None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag not in TAGS:
            self.bad.append(f"tag <{tag}>")
        if tag == "script" and a.get("type") != "application/json":
            self.bad.append(f"script {attrs}")
        self.in_script = tag if tag in ("script", "style") else None
        for k, v in attrs:
            if k.startswith("on") or k in ("srcdoc", "formaction"):
                self.bad.append(f"attribute {k}={v!r} on <{tag}>")
            if k in ("href", "src") and v and v.strip().lower().startswith(
                    ("javascript:", "data:", "vbscript:")):
                self.bad.append(f"link {k}={v!r}")
            if v is not None:
                self.texts.append(v)

    def handle_endtag(self, tag):
        self.in_script = None

    def handle_data(self, data):
        if self.in_script is None:
            self.texts.append(data)


def assert_inert(doc: str, where: str = "") -> Inert:
    """No markup from data in ``doc``; returns the parser (its texts: what a reader sees)."""
    lower = doc.lower()
    assert lower.count("<script") == lower.count('<script type="application/json"'), where
    assert lower.count("</script") == lower.count("<script"), where
    p = Inert()
    p.feed(doc)
    p.close()
    assert p.bad == [], f"{where}: {p.bad}"
    return p


def written_pages(root: Path) -> list[Path]:
    return sorted(root.rglob("*.html"))


def read(path: Path) -> str:
    """A page's text as written (no newline translation: a carriage return from data stays)."""
    return path.read_bytes().decode("utf-8")


#: Text for the fuzz: any, the payloads, and strings made of markup's characters.
texts = st.one_of(st.text(max_size=40), st.sampled_from(PAYLOADS),
                  st.text(alphabet="<>&\"'/=: scriptimgonerrorjavascript", max_size=40))
values = st.one_of(texts, st.floats(allow_nan=True), st.integers(), st.none(), st.booleans())
