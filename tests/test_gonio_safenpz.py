"""gonio.safenpz.load_npz: an .npz from others, every member's size known before a byte is
inflated (issue 35)."""

import io
import os
import zipfile

import numpy as np
import pytest
from numpy.lib import format as npformat

from gonio.safenpz import MAX_MEMBERS, load_npz


def _npy(arr, shape=None, dtype=None) -> bytes:
    """The .npy bytes of ``arr``, its header optionally claiming another shape or dtype."""
    buf = io.BytesIO()
    head = npformat.header_data_from_array_1_0(arr)
    if shape is not None:
        head["shape"] = shape
    if dtype is not None:
        head["descr"] = npformat.dtype_to_descr(np.dtype(dtype))
    npformat.write_array_header_1_0(buf, head)
    buf.write(arr.tobytes("F" if head["fortran_order"] else "C"))
    return buf.getvalue()


def _zip(path, members, compression=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


def test_arrays_round_trip_in_either_order_and_compression(tmp_path):
    a = np.arange(12.0).reshape(3, 4)
    f = np.asfortranarray(np.arange(6, dtype=np.int32).reshape(2, 3))
    for comp in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        p = _zip(tmp_path / f"a{comp}.npz", {"a.npy": _npy(a), "f.npy": _npy(f),
                                             "s.npy": _npy(np.array("digest"))}, comp)
        d = load_npz(p, ("a", "f", "s"))
        assert np.array_equal(d["a"], a) and np.array_equal(d["f"], f)
        assert d["f"].dtype == np.int32 and str(d["s"]) == "digest"
    p = tmp_path / "saved.npz"
    np.savez(p, x=np.linspace(0, 1, 5))                # what loo.npz is written with
    assert load_npz(p, ("x",))["x"].tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]


def test_a_highly_compressed_member_is_refused_before_it_is_inflated(tmp_path):
    zeros = np.zeros(1 << 20)                           # 8 MiB that deflate to ~8 KB
    p = _zip(tmp_path / "z.npz", {"z.npy": _npy(zeros)}, zipfile.ZIP_DEFLATED)
    with pytest.raises(ValueError, match=r"z\.npz: member 'z' inflates \d+ bytes to 8388\d+ "
                                         r"bytes \(ratio above 50"):
        load_npz(p, ("z",))


def test_a_member_larger_than_the_cap_is_refused_by_its_declared_size(tmp_path):
    p = _zip(tmp_path / "big.npz", {"x.npy": _npy(np.arange(1000.0))}, zipfile.ZIP_DEFLATED)
    assert p.stat().st_size < 5000                      # the file fits, the member does not
    with pytest.raises(ValueError, match=r"big\.npz: member 'x' declares 8\d\d\d bytes, more "
                                         r"than the 5000 bytes"):
        load_npz(p, ("x",), max_bytes=5000)
    assert load_npz(p, ("x",), max_bytes=20000)["x"][-1] == 999.0


def test_a_header_that_disagrees_with_the_member_is_refused(tmp_path):
    data = _npy(np.ones(10), shape=(10 ** 9,))         # claims 8 GB, holds 80 bytes
    p = _zip(tmp_path / "lie.npz", {"x.npy": data})
    with pytest.raises(ValueError, match=r"lie\.npz: member 'x' declares \d+ bytes but its "
                                         r"header says \(1000000000,\)"):
        load_npz(p, ("x",))


def test_objects_and_missing_members_are_refused(tmp_path):
    p = _zip(tmp_path / "o.npz", {"o.npy": _npy(np.zeros(2), dtype="O")})
    with pytest.raises(ValueError, match=r"o\.npz: member 'o' holds dtype '\|O'; .*never "
                                         r"objects"):
        load_npz(p, ("o",))
    with pytest.raises(ValueError, match=r"o\.npz: no member 'q' \(file holds o\)"):
        load_npz(p, ("q",))


def test_a_zip_of_too_many_members_is_refused_before_its_directory_is_read(tmp_path):
    p = _zip(tmp_path / "many.npz", {f"m{i}.npy": b"" for i in range(MAX_MEMBERS + 1)})
    with pytest.raises(ValueError, match=rf"many\.npz: a zip directory of {MAX_MEMBERS + 1} "
                                         r"members"):
        load_npz(p, ("m0",))


def test_a_link_a_fifo_and_not_a_zip_are_one_line(tmp_path):
    good = tmp_path / "good.npz"
    np.savez(good, x=np.ones(3))
    (tmp_path / "link.npz").symlink_to(good)
    os.mkfifo(tmp_path / "fifo.npz")
    (tmp_path / "text.npz").write_text("not a zip at all")
    for name, says in (("link.npz", "symbolic link"), ("fifo.npz", "FIFO"),
                       ("text.npz", "not a zip")):
        with pytest.raises(ValueError) as err:
            load_npz(tmp_path / name, ("x",))
        msg = str(err.value)
        assert msg.startswith(str(tmp_path / name)) and says in msg and "\n" not in msg, msg


def test_a_member_that_holds_less_than_it_declares_is_refused(tmp_path):
    arr = np.arange(4.0)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("x.npy", _npy(arr))
    raw = bytearray(buf.getvalue())
    # cut the last 8 bytes of the member's data, the sizes in both headers kept: a truncated
    # file whose directory still claims the whole array
    at = raw.index(b"PK\x01\x02")
    cut = raw[:at - 8] + raw[at:]
    offset_field = cut.index(b"PK\x05\x06") + 16
    cut[offset_field:offset_field + 4] = (at - 8).to_bytes(4, "little")
    (tmp_path / "cut.npz").write_bytes(bytes(cut))
    with pytest.raises(ValueError, match=r"cut\.npz"):
        load_npz(tmp_path / "cut.npz", ("x",))
