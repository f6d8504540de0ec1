"""HDF5 files from others read as data: the structure checked against a layout, then read.

An HDF5 file is a small file system. It can hold links to other files (external links),
paths that name other paths (soft links), one node under many names (hard links), datasets
whose bytes lie in another file (external raw storage) or are assembled from other datasets
(virtual datasets), and dataspaces that declare any size whatever the file holds (an
unwritten dataset of 10^11 values costs a few bytes). :func:`read_h5` reads a file that
microcyl wrote (a fit's ``checkpoint.h5``) as data only:

1. the file is opened once by :func:`gonio.safeopen.open_regular` (no link, no FIFO, its
   size capped) and h5py reads that open file object, never the name;
2. the tree is walked without following anything: each link's kind is read before the node
   it names is opened (hard links only), no node is opened twice, a group may hold no more
   entries than its :class:`H5Group` names, and every group, dataset and attribute must be
   one the layout names: a dataset stored in the file itself (contiguous or compact; not
   chunked, external or virtual), of the layout's kind and shape, without attributes;
   an attribute a scalar of the layout's kind;
3. the bytes the datasets declare are checked against :func:`gonio.memory.check_memory`;
4. only then are values read, and only those the layout named.

Every refusal is one ``ValueError`` line: ``FILE: FIELD must be ...; got ...``.

Examples
--------
>>> import tempfile, os, h5py, numpy as np
>>> p = os.path.join(tempfile.mkdtemp(), "a.h5")
>>> with h5py.File(p, "w") as f:
...     f["x"] = np.arange(3.0)
...     f.attrs["n"] = 3
>>> layout = H5Group({"x": H5Data(("n",))}, attrs={"n": "int"})
>>> doc = read_h5(p, layout, what="a test file")
>>> doc["x"].tolist(), int(doc["attr:n"])
([0.0, 1.0, 2.0], 3)
>>> read_h5(p, H5Group({"x": H5Data((2,))}, attrs={"n": "int"}),
...         what="a test file")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: ...a.h5: x must be an array of numbers of shape (2,); got shape (3,)
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field

import h5py

from gonio.memory import check_memory
from gonio.safeopen import open_regular
from gonio.statefields import FileFields, one_line

__all__ = ["H5Data", "H5Group", "read_h5", "BYTES_PER_VALUE"]

#: Memory planned per declared value: its read (at most 8 bytes) and one float64 copy.
BYTES_PER_VALUE = 16
#: The HDF5 type classes each kind of the layout allows, with the sizes (bytes) allowed.
_KINDS = {"number": ({h5py.h5t.FLOAT: (2, 4, 8), h5py.h5t.INTEGER: (1, 2, 4, 8)},
                     "an array of numbers", "a number"),
          "int": ({h5py.h5t.INTEGER: (1, 2, 4, 8)}, "an array of integers", "an integer"),
          "text": ({h5py.h5t.STRING: None}, "text", "text")}
_CLASSES = {getattr(h5py.h5t, k): k.lower() for k in (
    "INTEGER", "FLOAT", "TIME", "STRING", "BITFIELD", "OPAQUE", "COMPOUND", "REFERENCE", "ENUM",
    "VLEN", "ARRAY")}
_STORED = {h5py.h5d.CONTIGUOUS: "contiguous", h5py.h5d.COMPACT: "compact",
           h5py.h5d.CHUNKED: "chunked", getattr(h5py.h5d, "VIRTUAL", -1): "virtual"}


@dataclass(frozen=True)
class H5Data:
    """A dataset a layout allows.

    Parameters
    ----------
    shape : tuple
        Each length an int, or the name of a dimension: one name has one length wherever
        it appears (``"steps@0"`` is shown as ``steps``; the text after ``@`` scopes it).
    kind : str
        ``"number"`` (floats or integers) or ``"int"`` (integers).
    """

    shape: tuple
    kind: str = "number"


@dataclass(frozen=True)
class H5Group:
    """A group a layout allows: its entries (name -> :class:`H5Data` or :class:`H5Group`),
    its scalar attributes (name -> ``"number"``, ``"int"`` or ``"text"``) and the entries
    that may be absent (every attribute must be present)."""

    entries: Mapping[str, "H5Data | H5Group"]
    attrs: Mapping[str, str] = field(default_factory=dict)
    optional: frozenset = frozenset()

    def nodes(self) -> int:
        """Groups and datasets in the layout, this group included."""
        return 1 + sum(e.nodes() if isinstance(e, H5Group) else 1
                       for e in self.entries.values())


def read_h5(path, layout: H5Group, *, what: str, max_bytes: int | None = None,
            bounds: Mapping[str, int] | None = None, change: str = "") -> dict:
    """The values of the HDF5 file ``path`` that ``layout`` names, its structure checked
    first (module notes).

    Parameters
    ----------
    path : path
    layout : H5Group
        The root group's layout.
    what : str
        What the file is, for messages ("a fit's checkpoint").
    max_bytes : int, optional
        Largest file size (bytes); None: no cap.
    bounds : mapping, optional
        Largest length of a named dimension (by its shown name, ``steps``); others: any.
    change : str
        What to change when the declared values exceed the memory limit.

    Returns
    -------
    dict
        Per group a dict: its entries (a dict or an ndarray) and ``"attr:NAME"`` its
        attributes.

    Raises
    ------
    ValueError
        One line naming the file and the field: a link, a node reached twice, an entry,
        kind or shape the layout does not allow, more values than memory allows, or a file
        HDF5 cannot read.
    """
    with open_regular(path, max_bytes=max_bytes, what=what) as fh:
        try:
            with h5py.File(fh, "r") as f:
                walk = _Walk(path, layout.nodes(), dict(bounds or {}))
                tree = walk.group(f, layout, "")
                n = sum(math.prod(d.shape) for d, _, _ in walk.datasets)
                check_memory(f"{path}: its datasets declare {n:.3g} values, which",
                             n * BYTES_PER_VALUE, change or f"it is not {what}")
                for dset, doc, name in walk.datasets:
                    doc[name] = dset[()]
                for group, doc, name in walk.attrs:
                    doc[f"attr:{name}"] = group.attrs[name]
        except (OSError, KeyError, TypeError, RuntimeError) as exc:
            raise ValueError(f"{path}: corrupt, or not {what} (HDF5 cannot read it: "
                             f"{one_line(str(exc))})") from None
    return tree


class _Walk:
    """One walk of a file's tree against its layout: what passed, to be read after."""

    def __init__(self, path, max_nodes: int, bounds: dict):
        self.f, self.max_nodes, self.bounds = FileFields(path), max_nodes, bounds
        self.seen, self.dims = set(), {}
        self.datasets, self.attrs = [], []

    def _visit(self, obj, where: str):
        """Count a node and refuse one reached before (a hard link repeating it)."""
        info = h5py.h5o.get_info(obj.id)
        key = (info.fileno, info.addr)
        if key in self.seen:
            raise self.f.error(where, "a node of its own (each node under one name)",
                               got="a hard link to a node reached before")
        self.seen.add(key)
        if len(self.seen) > self.max_nodes:
            raise self.f.error(where, f"within {self.max_nodes} nodes",
                               got="more nodes than the layout has")
        return info

    def group(self, group, layout: H5Group, where: str) -> dict:
        """Check ``group`` and below; the dict its values will fill."""
        info = self._visit(group, where or "/")
        allowed = ", ".join(layout.entries) or "none"
        n = len(group)
        if n > len(layout.entries):
            raise self.f.error(where or "/", f"a group of at most {_count(len(layout.entries))} "
                               f"({allowed})", got=_count(n))
        doc, seen = {}, set()
        for name in group:
            here = f"{where}.{name}" if where else name
            if name not in layout.entries:
                raise self.f.error(here, f"absent (the entries allowed here: {allowed})",
                                   got="an entry")
            self._hard_link(group, name, here)
            obj, spec = group[name], layout.entries[name]
            seen.add(name)
            if isinstance(spec, H5Group):
                if not isinstance(obj, h5py.Group):
                    raise self.f.error(here, "a group", got=_node_kind(obj))
                doc[name] = self.group(obj, spec, here)
            else:
                self._visit(obj, here)
                self.dataset(obj, spec, here)
                self.datasets.append((obj, doc, name))
        missing = [k for k in layout.entries if k not in seen and k not in layout.optional]
        if missing:
            where_m = f"{where}.{missing[0]}" if where else missing[0]
            raise self.f.error(where_m, "present (microcyl writes it)")
        self._attributes(group, layout, where, info.num_attrs, doc)
        return doc

    def _hard_link(self, group, name: str, here: str):
        """Refuse a link that is not a hard link, before the node it names is opened."""
        try:
            link = group.get(name, getlink=True)
        except (TypeError, KeyError):
            link = None
        if isinstance(link, h5py.HardLink):
            return
        if isinstance(link, h5py.ExternalLink):
            got = f"an external link to {link.filename}:{link.path}"
        elif isinstance(link, h5py.SoftLink):
            got = f"a soft link to {link.path}"
        else:
            got = "a user-defined link"
        raise self.f.error(here, "a node of this file (a hard link)", got=got)

    def dataset(self, dset, spec: H5Data, here: str):
        """Check a dataset's storage, kind, shape and attributes (nothing read)."""
        if not isinstance(dset, h5py.Dataset):
            raise self.f.error(here, "a dataset", got=_node_kind(dset))
        dcpl = dset.id.get_create_plist()
        if dcpl.get_external_count() > 0:
            other = os.fsdecode(dcpl.get_external(0)[0])
            raise self.f.error(here, "a dataset stored in this file",
                               got=f"external raw storage in {other}")
        stored = dcpl.get_layout()
        if dset.is_virtual or stored not in (h5py.h5d.CONTIGUOUS, h5py.h5d.COMPACT):
            raise self.f.error(here, "a dataset stored contiguous or compact in this file, "
                               "as microcyl writes it",
                               got=f"{_STORED.get(stored, 'another')} storage")
        self._kind(dset.id.get_type(), spec.kind, here, 1)
        shape = dset.shape
        if shape is None or len(shape) != len(spec.shape):
            raise self.f.error(here, self._allowed(spec), got=f"shape {shape}")
        for n, s in zip(shape, spec.shape):
            self._length(here, spec, shape, n, s)
        if h5py.h5o.get_info(dset.id).num_attrs:
            raise self.f.error(f"{here}.attrs", "none (microcyl writes no attribute on a "
                               "dataset)", got="attributes")

    def _allowed(self, spec: H5Data) -> str:
        dims = ", ".join(str(s).split("@")[0] for s in spec.shape)
        return (f"{_KINDS[spec.kind][1]} of shape "
                f"({dims}{',' if len(spec.shape) == 1 else ''})")

    def _length(self, here: str, spec: H5Data, shape: tuple, n: int, s):
        """One length of a shape against the layout's: a number, or a named dimension."""
        if isinstance(s, int):
            if n != s:
                raise self.f.error(here, self._allowed(spec), got=f"shape {shape}")
            return
        name = s.split("@")[0]
        if s in self.dims and self.dims[s] != n:
            raise self.f.error(here, f"{self._allowed(spec)} with {name} = {self.dims[s]} "
                               f"(as elsewhere)", got=f"{name} = {n}")
        bound = self.bounds.get(name)
        if bound is not None and n > bound:
            raise self.f.error(here, f"{self._allowed(spec)} with {name} <= {bound}",
                               got=f"{name} = {n}")
        self.dims[s] = n

    def _kind(self, tid, kind: str, here: str, which: int):
        """An HDF5 type of the layout's kind (``which``: 1 a dataset's words, 2 a scalar's)."""
        classes, words = _KINDS[kind][0], _KINDS[kind][which]
        cls = tid.get_class()
        sizes = classes.get(cls, ())
        if cls not in classes or (sizes is not None and tid.get_size() not in sizes):
            raise self.f.error(here, words,
                               got=f"an HDF5 {_CLASSES.get(cls, 'unknown')} type of "
                                   f"{tid.get_size()} bytes")

    def _attributes(self, group, layout: H5Group, where: str, count: int, doc: dict):
        """Check a group's attributes: at most the layout's, each a scalar of its kind."""
        at = f"{where}.attrs" if where else "attrs"
        if count > len(layout.attrs):
            raise self.f.error(at, f"at most {len(layout.attrs)} attributes "
                               f"({', '.join(layout.attrs) or 'none'})", got=str(count))
        names = list(group.attrs)
        for name in list(layout.attrs):
            if name not in names:
                raise self.f.error(f"{where}.attr:{name}" if where else f"attr:{name}",
                                   "present (microcyl writes it)")
        for name in names:
            here = f"{where}.attr:{name}" if where else f"attr:{name}"
            if name not in layout.attrs:
                raise self.f.error(here, f"absent (the attributes allowed here: "
                                   f"{', '.join(layout.attrs) or 'none'})", got="an attribute")
            aid = group.attrs.get_id(name)
            if aid.shape != ():
                raise self.f.error(here, "a single value", got=f"shape {aid.shape}")
            self._kind(aid.get_type(), layout.attrs[name], here, 2)
            self.attrs.append((group, doc, name))


def _count(n: int) -> str:
    return f"{n} entr{'y' if n == 1 else 'ies'}"


def _node_kind(obj) -> str:
    """What an HDF5 node is, in words."""
    if isinstance(obj, h5py.Group):
        return "a group"
    if isinstance(obj, h5py.Dataset):
        return "a dataset"
    return "a named datatype" if isinstance(obj, h5py.Datatype) else "another kind of node"
