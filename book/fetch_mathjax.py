"""Put MathJax 4 where the book serves it from, book/_vendor/html/_static/mathjax (Sphinx copies
book/_vendor/html into the site, book/_config.yml), so that the site typesets offline; and axe-core,
the accessibility checker the browser tests inject into each built page, in book/_vendor/axe-core
(outside the site: the book does not serve it).

The npm registry's tarballs of MathJax, of its default font and of axe-core are fetched, each checked
against its pinned sha512 (the registry's ``dist.integrity``), and only the files used are unpacked:
MathJax's TeX-to-HTML component, the extensions it may load, and the font's glyph data and web fonts
(about 3.5 MB of the tarballs' 19), and axe-core's minified script.  `make`'s bootstrap runs this; it
does nothing when the pinned versions are in place, and it replaces the directory whole or not at all.

Usage: python3 book/fetch_mathjax.py [DIRECTORY]     (default book/_vendor)
"""

from __future__ import annotations

import base64
import hashlib
import io
import shutil
import sys
import tarfile
import tempfile
import urllib.request
from pathlib import Path

#: Per tarball: its address, its sha512 integrity, the paths in it to unpack (a folder ending in "/")
#: and where under DIRECTORY they go.  The font sits where the configuration's ``loader.paths.fonts``
#: ("[mathjax]") looks for it: mathjax/mathjax-newcm-font.
VERSION = "4.1.3"
AXE_VERSION = "4.14.1"
MATHJAX = "html/_static/mathjax/"
PINS = (
    (f"https://registry.npmjs.org/mathjax/-/mathjax-{VERSION}.tgz",
     "sha512-BN/8Pkgn7G1pIDYJqd9md+JHsE/jydSYbyOZnSdSA0WziuVO8mRxdYiWFumkVVly/8U+hm9DpIIoWuvySverzw==",
     ("LICENSE", "tex-chtml.js", "a11y/assistive-mml.js", "input/tex/extensions/"), MATHJAX),
    (f"https://registry.npmjs.org/@mathjax/mathjax-newcm-font/-/mathjax-newcm-font-{VERSION}.tgz",
     "sha512-gzAB3dFHilHX1l5x2xUqRL+1jDQt3Fyza1DkEMVXWC4E8SvsGdlgEza47HYi2WhVcgfkvf4zgUGzuhbq3Pjlew==",
     ("chtml/dynamic/", "chtml/woff2/"), MATHJAX + "mathjax-newcm-font/"),
    (f"https://registry.npmjs.org/axe-core/-/axe-core-{AXE_VERSION}.tgz",
     "sha512-FHfa+lmNjQZfJz1q8wKqIDwC6DExcHt/pkjNQb09a3NPjCKg2rhu5qb2S4r76ASyFNNtuFooJpZe37OgudVGtQ==",
     ("LICENSE", "axe.min.js"), "axe-core/"),
)
#: In DIRECTORY: the site's files (html/_static/mathjax/...), axe-core (axe-core/axe.min.js), and the
#: pins they were unpacked from.
MARK = "pins"


def _tarball(url, integrity):
    """The bytes at ``url``, refused unless their sha512 is ``integrity``."""
    try:
        with urllib.request.urlopen(url, timeout=120) as r:
            data = r.read()
    except OSError as e:
        raise SystemExit(f"fetch_mathjax: cannot fetch {url}: {e}") from None
    got = "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()
    if got != integrity:
        raise SystemExit(f"fetch_mathjax: {url} has sha512 {got}, pinned {integrity}; nothing written")
    return data


def fetch(directory):
    """Unpack the pinned files into ``directory``/html/_static/mathjax unless they are there already;
    return their size in bytes."""
    directory = Path(directory)
    pins = repr(PINS)
    if (directory / MARK).is_file() and (directory / MARK).read_text() == pins:
        return sum(p.stat().st_size for p in directory.rglob("*") if p.is_file() and p.name != MARK)
    directory.parent.mkdir(parents=True, exist_ok=True)
    new = Path(tempfile.mkdtemp(prefix=directory.name + ".", dir=directory.parent))
    try:
        for url, integrity, wanted, under in PINS:
            with tarfile.open(fileobj=io.BytesIO(_tarball(url, integrity)), mode="r:gz") as tar:
                for member in tar.getmembers():
                    name = member.name.removeprefix("package/")
                    if member.isfile() and ".." not in name.split("/") and any(
                            name == w or (w.endswith("/") and name.startswith(w)) for w in wanted):
                        target = new / under / name
                        target.parent.mkdir(parents=True, exist_ok=True)
                        target.write_bytes(tar.extractfile(member).read())
        (new / MARK).write_text(pins)
        shutil.rmtree(directory, ignore_errors=True)
        new.rename(directory)
    finally:
        shutil.rmtree(new, ignore_errors=True)
    return fetch(directory)


if __name__ == "__main__":
    if len(sys.argv) > 2:
        raise SystemExit(__doc__.strip().splitlines()[-1])
    where = Path(sys.argv[1]) if len(sys.argv) == 2 else Path(__file__).with_name("_vendor")
    print(f"fetch_mathjax: MathJax {VERSION} and axe-core {AXE_VERSION} in {where} ({fetch(where) / 1e6:.1f} MB)")
