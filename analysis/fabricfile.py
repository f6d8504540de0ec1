"""A fabric as a file: the ``microcylinder`` plugin's dictionary (JSON) and its XML element.

``microcyl export`` writes a fabric (a fit's posterior medians) as the dictionary of the Mitsuba
3 BSDF ``microcylinder`` (:func:`plugin_dict`, JSON) or as its ``<bsdf>`` element for scene
files (:func:`plugin_xml`); :func:`fabric_from_dict` and :func:`fabric_from_xml` read them back,
and :func:`read_fabric_file` reads either from a file. None of this needs Mitsuba
(:mod:`reports.mitsuba.plugin` registers the plugin itself and re-exports these names).

Such files come from others: they are read size-limited (:data:`MAX_FILE_BYTES`), the XML
without a document type (no entity is ever expanded) and every value checked by
:class:`brdf.Fabric`.
"""

from __future__ import annotations

import json
import math
import numbers
import xml.etree.ElementTree as ElementTree
from collections.abc import Mapping
from pathlib import Path
from xml.sax.saxutils import quoteattr

import brdf
from brdf.fabric import OPTIONS
from gonio.atomic import atomic_write
from gonio.jsonplain import plain
from gonio.safeopen import read_bytes
from gonio.statefields import MAX_MAGNITUDE, loads_json

__all__ = ["plugin_dict", "plugin_xml", "fabric_from_dict", "fabric_from_xml",
           "read_fabric_file", "write_fabric_file", "PLUGIN_NAME", "THREAD_KEYS", "OPTION_KEYS", "MAX_FILE_BYTES",
           "SUFFIXES"]

#: The plugin's name in Mitsuba's registry.
PLUGIN_NAME = "microcylinder"
#: Per-thread keys (with 1 or 2 appended): the fields of :class:`brdf.Thread`.
THREAD_KEYS = ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area", "offsets", "lengths")
#: Option keys: :data:`brdf.OPTIONS` (``rotation`` in degrees here).
OPTION_KEYS = tuple(OPTIONS)


def plugin_dict(fabric: brdf.Fabric, preset: str | None = None) -> dict:
    """The plugin's dictionary of ``fabric``: every thread parameter and option spelled out.

    Parameters
    ----------
    fabric : brdf.Fabric
    preset : str, optional
        The ``fabric`` key (default ``fabric.name``, else ``"linen_plain"``); every value is
        given explicitly, so the preset only names where the fabric came from.

    Returns
    -------
    dict
        JSON-ready; ``mi.load_dict`` takes it as it is (albedos as ``{"type": "rgb", ...}``,
        offsets and lengths as comma-separated strings, rotation in degrees).

    Examples
    --------
    >>> d = plugin_dict(brdf.fabric("velvet"))
    >>> d["type"], d["fabric"], d["offsets2"], d["lengths2"]
    ('microcylinder', 'velvet', '-90, -55, 55, 90', '0.5, 0, 0.5')
    >>> fabric_from_dict(d).threads == brdf.fabric("velvet").threads
    True
    """
    name = preset or fabric.name or "linen_plain"
    out = {"type": PLUGIN_NAME, "fabric": name}
    for j, t in enumerate(fabric.threads, start=1):
        for key in THREAD_KEYS:
            v = getattr(t, key)
            if key == "albedo":
                v = {"type": "rgb", "value": [float(c) for c in v]}
            elif key in ("offsets", "lengths"):
                v = ", ".join(_number(x) for x in v)
            out[f"{key}{j}"] = v
    for key, v in fabric.options.items():
        out[key] = math.degrees(v) if key == "rotation" else v
    return out


def plugin_xml(fabric: brdf.Fabric, preset: str | None = None, bsdf_id: str = "fabric") -> str:
    """The plugin's dictionary of ``fabric`` as a Mitsuba 3 XML ``<bsdf>`` element.

    Parameters
    ----------
    fabric : brdf.Fabric
    preset : str, optional
        As in :func:`plugin_dict`.
    bsdf_id : str
        The element's ``id``, for ``<ref id="..."/>`` in a scene file.

    Returns
    -------
    str
        A ``<bsdf type="microcylinder">`` element with every key of :func:`plugin_dict`
        (``boolean``, ``integer``, ``float``, ``string`` and ``rgb`` properties), to paste
        into a scene file that is loaded after :func:`register`.

    Examples
    --------
    >>> print(plugin_xml(brdf.fabric("velvet")).splitlines()[1])
        <string name="fabric" value="velvet"/>
    """
    lines = [f'<bsdf type="{PLUGIN_NAME}" id={quoteattr(bsdf_id)}>']
    for key, v in plugin_dict(fabric, preset).items():
        if key == "type":
            continue
        if isinstance(v, bool):
            tag, text = "boolean", "true" if v else "false"
        elif isinstance(v, int):
            tag, text = "integer", str(v)
        elif isinstance(v, float):
            tag, text = "float", repr(v)
        elif isinstance(v, Mapping):
            tag, text = "rgb", ", ".join(repr(float(c)) for c in v["value"])
        else:
            tag, text = "string", str(v)
        lines.append(f'    <{tag} name="{key}" value={quoteattr(text)}/>')
    return "\n".join(lines + ["</bsdf>"]) + "\n"


def _number(x) -> str:
    """The shortest text that reads back as the float x ("55", "1.33")."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def _finite(key, value, what: str = "a number") -> float:
    """``value`` as a float: a number (or its text), finite, of magnitude at most
    :data:`MAX_MAGNITUDE`; else a ValueError naming ``key``."""
    try:
        if isinstance(value, bool):
            raise TypeError
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{key} must be {what}; got {value!r:.60}") from None
    if not (math.isfinite(x) and abs(x) <= MAX_MAGNITUDE):
        raise ValueError(f"{key} must be finite, of magnitude at most {MAX_MAGNITUDE:g}; got "
                         f"{value!r:.60}")
    return x


def _floats(key, value) -> tuple:
    """A comma-separated string (or a number, or a sequence) as a tuple of floats."""
    what = "numbers separated by commas"
    if isinstance(value, str):
        parts = [p for p in value.replace(",", " ").split() if p]
    elif isinstance(value, numbers.Real):
        parts = [value]
    elif isinstance(value, (list, tuple)):
        parts = list(value)
    else:
        raise ValueError(f"{key} must be {what}; got {value!r:.60}")
    return tuple(_finite(key, p, what) for p in parts)


def _rgb(key, value) -> tuple:
    """An albedo given as a number, an RGB triple or an ``{"type": "rgb"}`` dictionary."""
    if isinstance(value, Mapping):
        if value.get("type") != "rgb" or "value" not in value:
            raise ValueError(f"{key} must be a number or {{'type': 'rgb', 'value': [r, g, b]}}; "
                             f"got {value!r}")
        value = value["value"]
    what = "a number or an RGB triple"
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return (_finite(key, value, what),) * 3
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise ValueError(f"{key} must be {what}; got {value!r:.60}")
    return tuple(_finite(key, v, what) for v in value)


def fabric_from_dict(props: Mapping) -> brdf.Fabric:
    """The :class:`brdf.Fabric` of a plugin dictionary (or of Mitsuba's properties as a dict).

    Parameters
    ----------
    props : mapping
        ``fabric`` (a preset of :data:`brdf.PRESETS`, default ``"linen_plain"``), any of
        ``{key}1`` / ``{key}2`` for :data:`THREAD_KEYS` and any of :data:`OPTION_KEYS`;
        ``type`` and ``id`` are ignored.

    Returns
    -------
    brdf.Fabric

    Raises
    ------
    ValueError
        An unknown key (the valid ones are listed), an unknown preset, a value out of range.

    Examples
    --------
    >>> fab = fabric_from_dict({"fabric": "velvet", "eta1": 1.5, "rotation": 90.0})
    >>> fab.threads[0].eta, fab.threads[1].eta, round(fab.options["rotation"], 6)
    (1.5, 1.46, 1.570796)
    """
    props = dict(props)
    props.pop("type", None)
    props.pop("id", None)
    name = props.pop("fabric", "linen_plain")
    threads = list(brdf.preset_threads(str(name)))
    valid = [f"{k}{j}" for j in (1, 2) for k in THREAD_KEYS] + list(OPTION_KEYS)
    unknown = sorted(set(props) - set(valid))
    if unknown:
        raise ValueError(f"unknown {PLUGIN_NAME} parameter(s) {', '.join(map(repr, unknown))}; "
                         f"valid: fabric, {', '.join(valid)}")
    for j in (1, 2):
        changes = {}
        for key in THREAD_KEYS:
            if f"{key}{j}" not in props:
                continue
            v = props[f"{key}{j}"]
            if key == "albedo":
                v = _rgb(f"albedo{j}", v)
            elif key in ("offsets", "lengths"):
                v = _floats(f"{key}{j}", v)
            else:
                v = _finite(f"{key}{j}", v)
            changes[key] = v
        try:
            threads[j - 1] = threads[j - 1].replace(**changes)
        except ValueError as exc:
            raise ValueError(f"thread {j}: {exc}") from None
    options = {k: props[k] for k in OPTION_KEYS if k in props}
    if "rotation" in options:
        options["rotation"] = math.radians(_finite("rotation", options["rotation"],
                                                   "a number of degrees"))
    return brdf.Fabric(threads, name=str(name), **options)


#: Largest fabric file read (bytes): an exported one is about 1.5 KB.
MAX_FILE_BYTES = 1 << 20
#: The suffixes of fabric files: the JSON dictionary and the XML element.
SUFFIXES = (".json", ".xml")
#: XML property tags and how their value attribute reads.
_XML_TYPES = {"boolean": None, "integer": int, "float": float, "string": str, "rgb": None}


def _xml_value(key: str, tag: str, text: str):
    """The value of one XML property (``<float name=... value=...>``) as the dictionary's."""
    if tag == "boolean":
        if text.strip().lower() not in ("true", "false"):
            raise ValueError(f"{key} must be true or false; got {text!r:.60}")
        return text.strip().lower() == "true"
    if tag == "rgb":
        parts = [p for p in text.replace(",", " ").split() if p]
        try:
            return {"type": "rgb", "value": [float(p) for p in parts]}
        except ValueError:
            raise ValueError(f"{key} must be three numbers; got {text!r:.60}") from None
    try:
        return _XML_TYPES[tag](text)
    except ValueError:
        raise ValueError(f"{key} must be {'an' if tag == 'integer' else 'a'} {tag}; "
                         f"got {text!r:.60}") from None


def fabric_from_xml(text: str) -> brdf.Fabric:
    """The :class:`brdf.Fabric` of a ``<bsdf type="microcylinder">`` element
    (:func:`plugin_xml`'s, or one in a scene file: the first such element).

    Parameters
    ----------
    text : str
        XML without a document type declaration (no entities: refused before parsing).

    Raises
    ------
    ValueError
        A document type, malformed XML, no microcylinder element, a property of another
        kind or without name and value, or what :func:`fabric_from_dict` refuses.

    Examples
    --------
    >>> fabric_from_xml(plugin_xml(brdf.fabric("velvet"))).threads == brdf.fabric("velvet").threads
    True
    """
    if "<!DOCTYPE" in text.upper() or "<!ENTITY" in text.upper():
        raise ValueError("a document type declaration (<!DOCTYPE, <!ENTITY) is not read")
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise ValueError(f"not well-formed XML ({exc})") from None
    elements = [root] if root.tag == "bsdf" else list(root.iter("bsdf"))
    bsdf = next((e for e in elements if e.get("type") == PLUGIN_NAME), None)
    if bsdf is None:
        raise ValueError(f'no <bsdf type="{PLUGIN_NAME}"> element')
    props = {}
    for child in bsdf:
        key, value = child.get("name"), child.get("value")
        if child.tag not in _XML_TYPES or key is None or value is None:
            raise ValueError(f"<{child.tag:.30}> in the {PLUGIN_NAME} element: expected "
                             f"{', '.join(_XML_TYPES)} with name and value")
        if key in props:
            raise ValueError(f"{key!r:.40} is given twice")
        props[key] = _xml_value(key, child.tag, value)
    return fabric_from_dict(props)


def _read_text(path: Path) -> str:
    """The text of a regular file of at most :data:`MAX_FILE_BYTES`, opened once
    (:func:`gonio.safeopen.read_bytes`: never through a link, never a FIFO or device)."""
    try:
        data = read_bytes(path, max_bytes=MAX_FILE_BYTES, what="a fabric file")
    except ValueError as exc:               # named again by read_fabric_file
        raise ValueError(str(exc).removeprefix(f"{path}: ")) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None


def read_fabric_file(path) -> brdf.Fabric:
    """The fabric of a file :func:`plugin_dict` (``.json``) or :func:`plugin_xml`
    (``.xml``) wrote, or one written by hand.

    Raises
    ------
    ValueError
        One line naming the file: another suffix, a link or special file, larger than
        :data:`MAX_FILE_BYTES`, unreadable, not a microcylinder dictionary or element, or a
        value :func:`fabric_from_dict` refuses.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix not in SUFFIXES:
            raise ValueError(f"a fabric file ends in {' or '.join(SUFFIXES)}")
        text = _read_text(path)
        if suffix == ".xml":
            return fabric_from_xml(text)
        try:        # one line for invalid or too deeply nested JSON
            doc = loads_json(text, path, "fabric dictionary")
        except ValueError as exc:
            raise ValueError(f"unreadable JSON ({str(exc).removeprefix(f'{path}: '):.80})") \
                from None
        if not isinstance(doc, dict) or doc.get("type", PLUGIN_NAME) != PLUGIN_NAME:
            kind = doc.get("type") if isinstance(doc, dict) else type(doc).__name__
            raise ValueError(f"must hold a {PLUGIN_NAME} plugin dictionary (a JSON object "
                             f"of type {PLUGIN_NAME!r}); got {kind!r:.40}")
        return fabric_from_dict(doc)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{path}: {exc}") from None


def write_fabric_file(path, fabric: brdf.Fabric, preset: str | None = None) -> Path:
    """Write ``fabric`` (what ``microcyl export`` does): as :func:`plugin_xml`'s element where
    ``path`` ends in ``.xml``, else as :func:`plugin_dict`'s dictionary in indented JSON;
    atomically (:func:`gonio.atomic_write`). Returns the path; :func:`read_fabric_file`
    reads it back.

    Examples
    --------
    >>> import tempfile
    >>> fab = brdf.fabric("velvet", masking=False)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     back = read_fabric_file(write_fabric_file(Path(tmp) / "v.xml", fab, "velvet"))
    >>> back.options["masking"], back.threads[0].eta == fab.threads[0].eta
    (False, True)
    """
    path = Path(path)
    if path.suffix.lower() == ".xml":
        text = plugin_xml(fabric, preset)
    else:
        text = json.dumps(plain(plugin_dict(fabric, preset)), indent=2) + "\n"
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return path
