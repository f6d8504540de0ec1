"""XML from others read as data: no document type, no entity, no external reference.

:func:`parse_xml` refuses a document type declaration or an entity before parsing (so no
entity is ever expanded and no external DTD or entity is fetched: the defusedxml rules) and
parses what is left with the standard library's ElementTree, which resolves no external
reference by itself. The file itself is read through :func:`gonio.safeopen.read_text`
(no link, regular files only, size capped).

Examples
--------
>>> parse_xml('<a x="1"/>').get("x")
'1'
>>> parse_xml('<!DOCTYPE a [<!ENTITY e "x">]><a>&e;</a>')
Traceback (most recent call last):
...
ValueError: a document type or entity declaration (<!DOCTYPE, <!ENTITY) is not read
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from gonio.safeopen import read_text

__all__ = ["parse_xml", "read_xml", "MAX_XML_BYTES"]

#: Largest XML export read back (bytes): an exported .mtlx is about 2 KB.
MAX_XML_BYTES = 1 << 20


def parse_xml(text: str) -> ElementTree.Element:
    """The root element of ``text``; a ValueError for a declaration or malformed XML."""
    upper = text.upper()
    if "<!DOCTYPE" in upper or "<!ENTITY" in upper:
        raise ValueError("a document type or entity declaration (<!DOCTYPE, <!ENTITY) is "
                         "not read")
    try:
        return ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise ValueError(f"not well-formed XML ({exc})") from None


def read_xml(path, what: str) -> ElementTree.Element:
    """The root element of the file ``path``; one ValueError line naming it otherwise."""
    text = read_text(path, max_bytes=MAX_XML_BYTES, what=what)
    try:
        return parse_xml(text)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
