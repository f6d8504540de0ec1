r"""A Mitsuba 3 plugin: the BSDF ``microcylinder``, microcyl's fabrics in Mitsuba's renderers.

After :func:`register` (with a Mitsuba RGB variant set),
``mi.load_dict({"type": "microcylinder", "fabric": "velvet"})`` is the preset, and every
thread parameter and option is a key of the same dictionary (:data:`THREAD_KEYS`,
:data:`OPTION_KEYS`): ``eta1``, ``albedo2`` (a number or ``{"type": "rgb", "value": [r, g,
b]}``), ``offsets1`` (degrees, a comma-separated string), ``masking``, ``rotation`` (degrees),
... Keys left out keep the preset's values and microcyl's defaults. ``albedo1`` and ``albedo2``
also take a Mitsuba texture (``bitmap``, ``checkerboard``, ...): f_r uses its value at each
hit, the sampler its mean (:data:`reports.mitsuba_bsdf.TEXTURED_KEYS`). ``mi.traverse`` exposes each
thread's ``eta``, ``albedo``, ``kd``, ``gamma_s``, ``gamma_v`` and ``area`` (1 or 2 appended) and
``rotation`` for editing (:data:`reports.mitsuba_bsdf.TRAVERSED_THREAD_KEYS`); a JIT variant
then reuses its compiled kernel. The kernel is written in
Dr.Jit (:mod:`reports.mitsuba_kernel`) and runs in ``scalar_rgb``, ``llvm_ad_rgb`` and
``cuda_ad_rgb``.

Conventions. Mitsuba's ``si.wi`` points toward the viewer and a BSDF's ``wo`` toward the light:
microcyl's ``wo`` and ``wi``. ``eval`` returns :math:`f_r(\omega_i, \omega_o)\cos\theta_i`
(the cosine on the light side), ``sample`` draws the light direction as
:func:`brdf.sampling.sample` does and returns ``(BSDFSample3f, f_r cos / pdf)``. The warp
follows the surface's first tangent ``dp_du`` projected onto the tangent plane, as microcyl's
renderer has the warp follow each primitive's tangent; ``rotation`` turns it further about n.
Mitsuba counts a draw of weight 0 as no draw, so the plugin's ``pdf`` is the density of
the draws of nonzero weight: :func:`brdf.sampling.pdf` where :math:`f_r\cos\theta_i > 0`, 0
elsewhere (below the horizon, where lobes spill, and where the model's f_r vanishes above it,
as it does for velvet seen at grazing angles: every tangent sample then faces away from the
light or the viewer). The BSDF is one-sided (``FrontSide``); wrap it in Mitsuba's
``twosided`` for cloth seen from both sides.

:func:`plugin_dict`, :func:`plugin_xml` and :func:`fabric_from_dict` need no Mitsuba: they
turn a :class:`brdf.Fabric` into the plugin's dictionary (or its XML ``<bsdf>`` element, for
scene files) and back (``microcyl export`` writes either for a fit's posterior medians).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from xml.sax.saxutils import quoteattr

import brdf
from brdf.fabric import OPTIONS
from gonio.statefields import MAX_MAGNITUDE

__all__ = ["register", "plugin_dict", "plugin_xml", "fabric_from_dict", "PLUGIN_NAME", "MAX_MAGNITUDE", "THREAD_KEYS",
           "OPTION_KEYS", "RGB_VARIANTS"]

#: The plugin's name in Mitsuba's registry.
PLUGIN_NAME = "microcylinder"
#: Per-thread keys (with 1 or 2 appended): the fields of :class:`brdf.Thread`.
THREAD_KEYS = ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area", "offsets", "lengths")
#: Option keys: :data:`brdf.OPTIONS` (``rotation`` in degrees here).
OPTION_KEYS = tuple(OPTIONS)
#: The variants the plugin supports (their spectra are RGB triples).
RGB_VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb")


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


def register() -> None:
    """Register the BSDF ``microcylinder`` with Mitsuba for the variant that is set.

    Call it after ``mitsuba.set_variant(...)`` (again after switching variants: a Mitsuba
    plugin class belongs to one variant).

    Raises
    ------
    ImportError
        Mitsuba is not installed.
    ValueError
        No variant is set, or it is not one of :data:`RGB_VARIANTS`' kind (``*_rgb``).
    """
    import mitsuba as mi  # optional dependency, loaded on use (and the plugin with it)

    variant = mi.variant()
    if variant is None or not variant.endswith("_rgb") or "polarized" in variant:
        raise ValueError(f"the {PLUGIN_NAME} BSDF needs an RGB variant "
                         f"({', '.join(RGB_VARIANTS)}); the variant set is {variant!r}")
    from reports import mitsuba_bsdf   # imports mitsuba and drjit at its top

    mi.register_bsdf(PLUGIN_NAME, lambda props: mitsuba_bsdf.bsdf_class()(props))
