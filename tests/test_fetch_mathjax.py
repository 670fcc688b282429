"""book/fetch_mathjax.py, on tarballs made here and read from file: addresses (no network): only the
pinned paths unpacked, a second run a no-op, and a tarball whose digest is not the pinned one refused
with nothing written."""

import base64
import hashlib
import io
import sys
import tarfile
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "book"))
import fetch_mathjax  # noqa: E402


def _tarball(path, files):
    """An npm-style tarball of ``files`` ({name: bytes}, under package/) at ``path``: (its address, its integrity)."""
    data = io.BytesIO()
    with tarfile.open(fileobj=data, mode="w:gz") as tar:
        for name, body in files.items():
            info = tarfile.TarInfo("package/" + name)
            info.size = len(body)
            tar.addfile(info, io.BytesIO(body))
    path.write_bytes(data.getvalue())
    return path.as_uri(), "sha512-" + base64.b64encode(hashlib.sha512(data.getvalue()).digest()).decode()


def test_fetch_unpacks_the_pinned_paths_once_and_refuses_another_tarball(tmp_path, monkeypatch):
    url, integrity = _tarball(tmp_path / "mathjax.tgz", {"tex-chtml.js": b"mj", "node-main.js": b"node",
                                                         "input/tex/extensions/ams.js": b"ams",
                                                         "input/tex/extensions/../../../escape.js": b"x"})
    monkeypatch.setattr(fetch_mathjax, "PINS", ((url, integrity, ("tex-chtml.js", "input/tex/extensions/"), fetch_mathjax.MATHJAX),))
    where = tmp_path / "vendor"
    assert fetch_mathjax.fetch(where) == 5
    mathjax = where / "html" / "_static" / "mathjax"
    assert sorted(p.relative_to(where).as_posix() for p in where.rglob("*") if p.is_file()) == \
        ["html/_static/mathjax/input/tex/extensions/ams.js", "html/_static/mathjax/tex-chtml.js", "pins"]
    (tmp_path / "mathjax.tgz").unlink()
    assert fetch_mathjax.fetch(where) == 5                        # in place: nothing fetched

    url, _ = _tarball(tmp_path / "other.tgz", {"tex-chtml.js": b"another"})
    monkeypatch.setattr(fetch_mathjax, "PINS", ((url, integrity, ("tex-chtml.js",), fetch_mathjax.MATHJAX),))
    with pytest.raises(SystemExit, match=r"other\.tgz has sha512 .*, pinned sha512-.*; nothing written"):
        fetch_mathjax.fetch(where)
    assert (mathjax / "tex-chtml.js").read_bytes() == b"mj"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.tgz", "vendor"]      # no half-written copy
