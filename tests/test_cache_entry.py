"""A cache file is used only when it proves it is whole and was computed from what is asked for
(poseintegrity.cache_entry): every damage, wherever it lands, is found, and nothing half-written is ever left."""

import errno
import io
import os
import zipfile

import numpy as np
import pytest

import poseintegrity.cache_entry as C
from poseintegrity import atomic_write
from poseintegrity.atomic_write import DiskFullError, remove_staging_files
from poseintegrity.kernel_pin import kernel_level

ARRAYS = {"points": np.arange(12, dtype=np.float32).reshape(6, 2), "name": np.array("usac_magsac"),
          "count": np.array(7)}


def written(tmp_path, key="k1"):
    path = tmp_path / "entry.npz"
    C.write_entry(path, key, ARRAYS)
    return path


def same(found, arrays=ARRAYS):
    assert not isinstance(found, C.Miss), found
    assert found.keys() == arrays.keys()
    for name, array in arrays.items():
        assert found[name].dtype == array.dtype and np.array_equal(found[name], array)


def test_an_entry_reads_back_as_written_and_its_bytes_repeat(tmp_path):
    path = written(tmp_path)
    same(C.read_entry(path, "k1"))
    first = path.read_bytes()
    C.write_entry(path, "k1", ARRAYS)
    assert path.read_bytes() == first  # the same arrays and key: the same bytes (no time or random name inside)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["entry.npz"]  # no staging file left


def test_a_missing_file_another_key_or_other_libraries_are_misses(tmp_path, monkeypatch):
    assert C.read_entry(tmp_path / "nothing.npz", "k1") == C.Miss("missing")
    path = written(tmp_path)
    assert C.read_entry(path, "k2") == C.Miss("stale")
    monkeypatch.setattr(C, "provenance", lambda: "another OpenCV")
    assert C.read_entry(path, "k1") == C.Miss("stale")  # computed by other code or kernels


def test_a_folder_in_its_place_is_unreadable(tmp_path):
    (tmp_path / "entry.npz").mkdir()
    assert C.read_entry(tmp_path / "entry.npz", "k1") == C.Miss("unreadable")


def test_every_cut_is_found(tmp_path):
    path = written(tmp_path)
    data = path.read_bytes()
    for length in range(0, len(data), 7):
        path.write_bytes(data[:length])
        assert C.read_entry(path, "k1") == C.Miss("damaged"), length


def test_a_flipped_bit_anywhere_is_found(tmp_path):
    """Bits flipped at seeded places over the whole file, zip headers (which a zip reader does not check) and the
    trailer included: each is found, none gives arrays."""
    path = written(tmp_path)
    data = bytearray(path.read_bytes())
    rng = np.random.default_rng(51)
    for position in [*rng.integers(0, len(data), 300), 0, 30, len(data) - 1, len(data) - 40]:
        flipped = data.copy()
        flipped[position] ^= 1 << int(rng.integers(8))
        path.write_bytes(flipped)
        assert C.read_entry(path, "k1") == C.Miss("damaged"), position


def test_a_whole_npz_of_the_older_format_is_stale_and_a_cut_one_damaged(tmp_path):
    """An .npz a plain writer made (np.savez: the format before trailers) is whole but cannot say what it was
    computed from: recomputed as stale, never used."""
    path = tmp_path / "old.npz"
    np.savez(path, key=np.array("k1"), **ARRAYS)
    assert C.read_entry(path, "k1") == C.Miss("stale")
    path.write_bytes(path.read_bytes()[:-10])
    assert C.read_entry(path, "k1") == C.Miss("damaged")


def test_misses_are_counted_per_block_and_described(tmp_path):
    path = written(tmp_path)
    with C.counting() as tally:
        C.read_entry(path, "k1")
        C.read_entry(tmp_path / "none.npz", "k1")
        C.read_entry(path, "other")
    assert tally == {"checked": 3, "missing": 1, "stale": 1}
    assert C.describe(tally) == "1 of 3 cache files recomputed (1 stale: other inputs, params, code or file format), 1 new"
    assert C.describe({"checked": 1441}) == "1 441 cache files whole and current"
    assert C.describe({"checked": 4, "damaged": 2, "unreadable": 1}) == (
        "3 of 4 cache files recomputed (1 unreadable, 2 damaged: cut short or altered)")
    result, counted = C.tallied(lambda p: C.read_entry(p, "k1"), tmp_path / "none.npz")
    assert result == C.Miss("missing") and counted == {"checked": 1, "missing": 1}


class CutShort(io.RawIOBase):
    """A file whose writer is interrupted (Ctrl-C, a killed worker's exception) halfway through its first write."""

    def __init__(self, stream):
        self.stream = stream

    def writable(self):
        return True

    def write(self, data):
        self.stream.write(data[: len(data) // 2])
        self.stream.flush()
        raise KeyboardInterrupt

    def close(self):
        self.stream.close()
        super().close()


def test_an_interrupted_write_keeps_the_old_file_and_leaves_no_staging_file(tmp_path, monkeypatch):
    """Interrupted halfway through writing the staging file: the old entry stays, whole, and the staging file goes;
    the writer leaves a partial file only when its process is killed (removed by the next run: below)."""
    path = written(tmp_path)
    before = path.read_bytes()
    fdopen = os.fdopen
    monkeypatch.setattr(atomic_write.os, "fdopen", lambda handle, mode: CutShort(fdopen(handle, mode)))
    with pytest.raises(KeyboardInterrupt):
        C.write_entry(path, "k2", ARRAYS)
    monkeypatch.undo()
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["entry.npz"]


class FullDisk(io.RawIOBase):
    """A file on a full disk: its first write fails with ENOSPC."""

    def __init__(self, handle, mode):
        os.close(handle)

    def writable(self):
        return True

    def write(self, data):
        raise OSError(errno.ENOSPC, "No space left on device")


def test_a_full_disk_names_the_file_and_the_free_space_and_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(atomic_write.os, "fdopen", FullDisk)
    path = tmp_path / "deep" / "entry.npz"
    with pytest.raises(DiskFullError) as raised:
        C.write_entry(path, "k1", ARRAYS)
    message = str(raised.value)
    assert "\n" not in message and str(path) in message and " free there" in message
    assert "no space left on device" in message
    assert list((tmp_path / "deep").iterdir()) == []


def test_a_killed_writer_s_staging_files_are_removed_and_nothing_else(tmp_path):
    path = written(tmp_path)
    (tmp_path / "images").mkdir()
    (tmp_path / "images" / ".s00_i00.npz.x1y2.partial").write_bytes(b"PK half")  # as write_atomically names them
    (tmp_path / ".entry.npz.abc.partial").write_bytes(b"")
    assert remove_staging_files(tmp_path) == 2
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["entry.npz", "images"]
    assert remove_staging_files(tmp_path / "nowhere") == 0
    same(C.read_entry(path, "k1"))


def test_the_key_holds_the_pinned_kernel_level_not_the_cpu(monkeypatch):
    """Pinned, every x86-64 machine computes with the same kernels: the same key (and the same file) everywhere;
    native, the key names this CPU."""
    assert kernel_level({}) == "AVX2, OpenCV without IPP"
    assert kernel_level({"POSEINTEGRITY_CPU_DISPATCH": "native"}).startswith("native ")
    assert "AVX2" in C.provenance() and "AVX512" not in C.provenance()


def test_the_stored_file_is_an_npz_any_reader_opens(tmp_path):
    """Before its trailer, the file is a plain .npz: a user can inspect a cache entry with numpy."""
    data = written(tmp_path).read_bytes()[:-C.TRAILER]
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.testzip() is None
    with np.load(io.BytesIO(data)) as stored:
        assert np.array_equal(stored["points"], ARRAYS["points"]) and C.KEY in stored.files
