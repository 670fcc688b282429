"""Rebuild and check the book's figures (a maintainer's tool).

    python book/check_figures.py --out DIR [--pages s1,s4]      # run the pages, write every figure
    python book/check_figures.py --check DIR [--ignore ID ...]  # run them afresh and compare with DIR

Each page of the book (book/_toc.yml order) runs in a fresh kernel; every PNG
figure it shows or glues is re-encoded from its pixels without metadata (two runs
give the same bytes) into DIR, with manifest.json (figure id, page, code cell,
content hash, the code version).  ``--check`` refuses a malformed or tampered DIR
before any page runs, then reports each figure that changed and by how much
(max |dI|), and exits 1 on a change beyond `CHECK_TOLERANCE_LEVELS` /
`CHECK_TOLERANCE_FRACTION`.

Exit paths are `renderer.cmdline`'s, as ``symrender``'s: an error prints one
line and exits 2, a bug one line and 1, SIGINT 130 and SIGTERM 143 (at any
moment, a page's run included).  DIR is written through a staging directory,
moved into place only after the report is written: a failed, interrupted or
terminated run, or one whose report cannot be written, leaves DIR as it was
and no staging or temporary directory.
"""

from __future__ import annotations

import asyncio
import contextlib
import hashlib
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from renderer import cmdline, files
from renderer.cmdline import UsageError, one_line

ROOT = Path(__file__).resolve().parents[1]


def _repo_root():
    return ROOT


def _book_pages(book):
    """Page names of the book in table-of-contents order (book/_toc.yml)."""
    import yaml
    toc = yaml.safe_load((book / "_toc.yml").read_text())
    pages = [toc["root"]]
    for ch in toc.get("chapters", []):
        pages.append(ch["file"])
    return pages


def _code_version(root):
    """The code a run used: the git commit (and whether the tree differs from it) and the
    project's source digest (`lab.store.source_digest`), so a manifest says which code it
    came from without timestamps."""
    from lab.store import source_digest
    version = {"source_sha256": source_digest(), "git_commit": None, "git_dirty": None}
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True)
        if head.returncode == 0:
            version["git_commit"] = head.stdout.strip()
            st = subprocess.run(["git", "status", "--porcelain", "--", "renderer", "proofs", "lab", "book"],
                                cwd=root, capture_output=True, text=True)
            version["git_dirty"] = bool(st.stdout.strip()) if st.returncode == 0 else None
    except OSError:
        pass
    return version


def _png_pixels(data):
    """Decode PNG bytes to an (H, W, 4) uint8 RGBA array."""
    cmdline.import_matplotlib()
    import matplotlib.image
    rgba = matplotlib.image.imread(io.BytesIO(data), format="png")
    if rgba.dtype != np.uint8:
        rgba = np.round(np.clip(rgba, 0, 1) * 255).astype(np.uint8)
    if rgba.ndim == 2:
        rgba = np.repeat(rgba[..., None], 3, axis=2)
    if rgba.shape[2] == 3:
        rgba = np.concatenate([rgba, np.full(rgba.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return rgba


#: A book code cell with this tag draws measured run times: its figures are
#: recorded with "varies" in the manifest, and --check reports them without failing.
VARIES_TAG = "measured-timing"


def _page_client():
    """nbclient's NotebookClient, answering SIGINT and SIGTERM while a page runs as the
    tool does: the signal is recorded (`renderer.cmdline.record_signal`) and the page's
    task cancelled, once; nbclient shuts its kernel down on the way out.  (nbclient's
    own handlers, which these replace once the kernel is up, do the same without
    telling which signal came.)"""
    import nbclient

    class PageClient(nbclient.NotebookClient):
        @contextlib.asynccontextmanager
        async def async_setup_kernel(self, **kwargs):
            async with super().async_setup_kernel(**kwargs):
                loop, task = asyncio.get_running_loop(), asyncio.current_task()

                def stop(signum):
                    if cmdline.record_signal(signum):
                        task.cancel()
                for sig in (signal.SIGINT, signal.SIGTERM):
                    with contextlib.suppress(RuntimeError):      # not the main thread
                        loop.add_signal_handler(sig, stop, sig)
                yield
    return PageClient


def _page_figures(book, page):
    """Execute one book page (a MyST notebook) in a fresh kernel; yield
    (figure id, code-cell ordinal, cell source, PNG bytes, cell tags) for every
    PNG it displays or glues.

    Raises
    ------
    UsageError
        If a cell fails (the page's exception, in one line).
    RuntimeError
        If the kernel dies (with the last line it wrote to its standard error,
        which is kept off the tool's: its warnings are not the tool's messages).
    KeyboardInterrupt
        If a signal stopped the page (whatever nbclient raised on its way out).
    """
    import base64

    import nbclient
    from myst_nb.core.read import read_myst_markdown_notebook

    path = book / f"{page}.md"
    nb = read_myst_markdown_notebook(path.read_text(encoding="utf-8"), path=path)
    client = _page_client()(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(book)}})
    # nbclient takes SIGINT and SIGTERM while it runs and leaves them at their defaults after:
    # the tool's handlers are put back.
    handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    with tempfile.TemporaryFile() as kernel_stderr:
        try:
            client.execute(stderr=kernel_stderr)    # the kernel is shut down on the way out, a signal included
        except BaseException as exc:
            cmdline.check_signal()                  # a signal stopped the page
            if isinstance(exc, nbclient.exceptions.CellExecutionError):
                raise UsageError(f"page {page} failed: {exc.ename}: {exc.evalue}") from None
            if isinstance(exc, nbclient.exceptions.DeadKernelError):
                kernel_stderr.seek(0)
                last = [line for line in kernel_stderr.read().decode(errors="replace").splitlines() if line.strip()]
                raise RuntimeError(f"page {page}: the kernel died ({(last or ['no message'])[-1]})") from None
            if isinstance(exc, asyncio.CancelledError):     # nbclient's own handler, before the tool's
                raise KeyboardInterrupt from None
            raise
        finally:
            for sig, handler in handlers.items():
                if handler is not None:
                    signal.signal(sig, handler)
    ordinal = 0
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        ordinal += 1
        j = 0
        for o in cell.get("outputs", []):
            data = o.get("data", {})
            key = next((k for k in data if k == "image/png" or k.endswith("record/image/png")), None)
            if key is None:
                continue
            meta = o.get("metadata", {})       # chapter.page.show names its figure outside a book build
            glue = ((meta.get("scrapbook") or {}).get("name") or (meta.get("symrender") or {}).get("figure"))
            j += 1
            fid = f"{page}-{glue}" if glue else f"{page}-cell{ordinal:02d}-{j}"
            tags = tuple(cell.get("metadata", {}).get("tags", ()))
            yield fid, ordinal, cell.source, base64.b64decode(data[key]), tags


def _resolve_pages(pages):
    """The book's pages to run: all (None) or the named ones, by name or by
    section prefix (s4 -> s4_simulator)."""
    all_pages = _known_pages()
    if pages is None:
        return all_pages
    resolved = []
    for p in pages:  # a page by name or by its section prefix: s4 -> s4_simulator
        match = [q for q in all_pages if q == p or q.startswith(f"{p}_")]
        if len(match) != 1:
            raise UsageError(f"--pages: unknown page {p!r}; pages are {', '.join(all_pages)}")
        resolved.append(match[0])
    return resolved


def _render_figures(out_dir, pages):
    """Execute the book's ``pages`` and write every figure into ``out_dir``
    (PNG, re-encoded from its pixels without metadata) plus ``manifest.json``.
    Returns the manifest (a dict)."""
    root = _repo_root()
    book = root / "book"
    figures = []
    for page in cmdline.progress(pages, desc="figures", unit="page"):
        for fid, ordinal, source, png, tags in _page_figures(book, page):
            rgba = _png_pixels(png)
            name = _figure_file_name(fid, {f["file"] for f in figures})
            data = cmdline.png_bytes(rgba)
            files.write_bytes(out_dir / name, data)
            entry = {"id": fid, "page": page, "code_cell": ordinal, "file": name,
                     "width": int(rgba.shape[1]), "height": int(rgba.shape[0]),
                     "sha256": hashlib.sha256(data).hexdigest(),
                     "cell_sha256": hashlib.sha256(source.encode()).hexdigest()}
            if VARIES_TAG in tags:
                # A plot of measured run times: it cannot repeat bit for bit.
                entry["varies"] = "measured timing"
            figures.append(entry)
    manifest = {"code_version": _code_version(root), "pages": list(pages), "figures": figures}
    text = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
    files.write_bytes(out_dir / "manifest.json", text.encode())
    return manifest


class _StagedDir:
    """A staging directory beside ``out_dir`` (``.<name>.XXXX.part``) for `_render_figures`;
    `commit` moves the result in (the whole directory if ``out_dir`` is new, else file by
    file with manifest.json last), `discard` removes it: ``out_dir`` is left as it was
    until the commit (a `renderer.cmdline.Outputs` staged output)."""

    def __init__(self, out_dir):
        self.out_dir = out_dir
        try:
            self.path = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name[:64]}.", suffix=".part"))
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(out_dir)) from None

    def commit(self):
        try:
            os.chmod(self.path, 0o777 & ~files.umask())
            if not self.out_dir.exists():
                os.replace(self.path, self.out_dir)
            else:
                names = sorted(p.name for p in self.path.iterdir() if p.name != "manifest.json")
                for name in [*names, "manifest.json"]:
                    os.replace(self.path / name, self.out_dir / name)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(self.out_dir)) from None
        finally:
            self.discard()

    def discard(self):
        shutil.rmtree(self.path, ignore_errors=True)


#: Largest manifest.json that ``figures --check`` reads (bytes); the whole
#: book's manifest is a few KiB.
MAX_MANIFEST_BYTES = 1 << 20
#: Largest previous figure file that ``--check`` reads (bytes); a book figure
#: is some tens of KiB, and an 8192^2 RGBA PNG that does not compress at all
#: is 256 MiB, far beyond any figure worth comparing.
MAX_FIGURE_BYTES = 64 << 20
#: Largest side (pixels) of a figure a manifest may declare.
MAX_FIGURE_SIDE = 8192
#: A figure file: a plain name inside the directory.
_FIGURE_FILE = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*\.png\Z")
_SHA256 = re.compile(r"[0-9a-f]{64}\Z")
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

#: Figures whose previous and fresh pixels differ by at most this many 8-bit
#: levels in every channel, on at most `CHECK_TOLERANCE_FRACTION` of their
#: pixels, are reported "within tolerance" and do not fail ``--check``.
#: Bit-identity cannot hold across machines: numpy picks a SIMD loop for
#: pow, exp, sin and log at run time from what the CPU offers, and the loops
#: round differently in the last bit.  A figure that plots such values (the
#: U-curve's step grid from logspace, a roundoff measured in float64) then
#: moves its lines by a small fraction of a pixel; only the antialiased edge
#: pixels change, and, along a dashed or dotted line, the phase of every dash,
#: each by part of the line's contrast.  A real change of a figure (a curve
#: that moves by a pixel, a different image) changes more pixels or more
#: levels than that.  `make test-baseline-simd` and ``figures --check`` across
#: ``NPY_DISABLE_CPU_FEATURES`` settings show the differences that occur.
CHECK_TOLERANCE_LEVELS = 32
#: See `CHECK_TOLERANCE_LEVELS`: the most pixels, as a fraction of the
#: figure, that may differ for it to count as within tolerance.
CHECK_TOLERANCE_FRACTION = 0.02


def _figure_file_name(fid, taken):
    """A plain file name for figure ``fid`` (characters outside [A-Za-z0-9._-]
    become ``_``), distinct from the names in ``taken``."""
    base = re.sub(r"[^A-Za-z0-9._-]", "_", fid).lstrip(".").replace("..", "_") or "figure"
    name, k = f"{base}.png", 1
    while name in taken:
        k += 1
        name = f"{base}-{k}.png"
    return name


def _known_pages():
    book = _repo_root() / "book"
    if not (book / "_toc.yml").is_file():
        raise UsageError(f"figures needs a source checkout: {str(book / '_toc.yml')!r} not found")
    return _book_pages(book)


def _manifest_error(path, what):
    return UsageError(f"--check: {str(path)!r} is not a valid symrender manifest: {what}")


def _validate_manifest(doc, path, known_pages):
    """Check a parsed manifest's structure; return ``(figures by id, pages)``."""
    bad = lambda what: _manifest_error(path, what)  # noqa: E731
    if not isinstance(doc, dict):
        raise bad(f"a JSON object is needed, got {type(doc).__name__}")
    pages = doc.get("pages")
    if not (isinstance(pages, list) and pages and all(isinstance(p, str) for p in pages)):
        raise bad('"pages" must be a non-empty list of page names')
    unknown = [p for p in pages if p not in known_pages]
    if unknown:
        raise bad(f"unknown page {unknown[0][:80]!r} in \"pages\"; pages are {', '.join(known_pages)}")
    version = doc.get("code_version", {})
    if not (isinstance(version, dict)
            and all(isinstance(version.get(k), (str, type(None))) for k in ("git_commit", "source_sha256"))):
        raise bad('"code_version" must be an object with string git_commit and source_sha256')
    entries = doc.get("figures")
    if not isinstance(entries, list):
        raise bad('"figures" must be a list')
    figures, names = {}, set()
    for i, f in enumerate(entries):
        if not isinstance(f, dict):
            raise bad(f"figures[{i}] must be an object")
        for key in ("id", "file", "sha256"):
            if not isinstance(f.get(key), str) or not f[key]:
                raise bad(f"figures[{i}].{key} must be a non-empty string")
        for key in ("width", "height"):
            v = f.get(key)
            if type(v) is not int or not 1 <= v <= MAX_FIGURE_SIDE:
                raise bad(f"figures[{i}].{key} must be an integer in [1, {MAX_FIGURE_SIDE}], got {v!r:.40}")
        name = f["file"]
        if not _FIGURE_FILE.match(name) or ".." in name:
            raise bad(f"figures[{i}].file {name[:80]!r} must be a plain file name in the directory "
                      "(letters, digits, '.', '_', '-', ending .png; no '/' or '..')")
        if not _SHA256.match(f["sha256"]):
            raise bad(f"figures[{i}].sha256 must be 64 lowercase hex digits")
        if not isinstance(f.get("varies", ""), str):
            raise bad(f"figures[{i}].varies must be a string")
        if f.get("page") not in pages:
            raise bad(f"figures[{i}].page must be one of the manifest's pages, got {f.get('page')!r:.80}")
        if f["id"] in figures:
            raise bad(f"figure id {f['id'][:80]!r} appears twice")
        if name in names:
            raise bad(f"file {name!r} is listed twice")
        figures[f["id"]] = f
        names.add(name)
    return figures, pages


def _read_figure(old_dir, entry):
    """The bytes of a previous figure file, checked against its manifest entry:
    a regular file (not a link) of at most `MAX_FIGURE_BYTES`, with the
    manifest's SHA-256, a PNG whose header declares the manifest's size."""
    path = Path(old_dir) / entry["file"]
    try:
        data = files.read_regular(path, MAX_FIGURE_BYTES, follow=False)
    except files.RefusedPath as exc:
        raise UsageError(f"--check: figure {entry['id']!r}: {exc}") from None
    except OSError as exc:
        raise UsageError(f"--check: figure {entry['id']!r}: cannot read {str(path)!r}: "
                         f"{exc.strerror or exc}") from None
    if hashlib.sha256(data).hexdigest() != entry["sha256"]:
        raise UsageError(f"--check: {str(path)!r} does not match its sha256 in manifest.json "
                         "(the directory was changed after it was written)")
    size = (int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big"))
    if data[:8] != _PNG_SIGNATURE or data[12:16] != b"IHDR" or size != (entry["width"], entry["height"]):
        raise UsageError(f"--check: {str(path)!r} is not a {entry['width']}x{entry['height']} PNG, "
                         "as manifest.json says")
    return data


def _decode_figure(data, what):
    """`_png_pixels` of a checked figure; a corrupt PNG is a usage error."""
    try:
        return _png_pixels(data)
    except Exception as exc:  # PIL and matplotlib raise many kinds on bad data
        raise UsageError(f"--check: {what} is not a readable PNG ({type(exc).__name__})") from None


def _load_manifest(old_dir, known_pages):
    """Read and validate ``old_dir/manifest.json`` and every figure file it lists
    before any page runs.

    Returns
    -------
    (doc, figures, pages) : the manifest (dict), its figure entries by id, its page names.

    Raises
    ------
    UsageError
        If manifest.json is not a regular file (a link, FIFO or device) of
        at most `MAX_MANIFEST_BYTES`, not UTF-8 JSON, or not a manifest: an
        object with a non-empty list of known ``pages`` and a list of
        ``figures``, each with a unique string ``id``, a plain ``file`` name
        inside ``old_dir``, a 64-hex-digit ``sha256`` and integer ``width``,
        ``height`` in [1, 8192]; or if a listed file is not a regular file of
        at most `MAX_FIGURE_BYTES`, does not match its sha256, or is not a
        PNG of the stated size.
    """
    if not str(old_dir):
        raise UsageError("--check: the directory path is empty")
    path = Path(old_dir) / "manifest.json"
    try:
        raw = files.read_regular(path, MAX_MANIFEST_BYTES, follow=False)
    except files.RefusedPath as exc:
        raise UsageError(f"--check: {exc}") from None
    except OSError as exc:
        raise UsageError(f"--check: cannot read {str(path)!r}: {exc.strerror or exc}") from None
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (ValueError, RecursionError) as exc:  # bad UTF-8, bad JSON, nesting too deep
        raise _manifest_error(path, f"not JSON ({one_line(exc)[:120]})") from None
    figures, pages = _validate_manifest(doc, path, known_pages)
    for entry in figures.values():
        _read_figure(old_dir, entry)
    for entry in figures.values():
        _decode_figure(_read_figure(old_dir, entry), repr(str(Path(old_dir) / entry["file"])))
    return doc, figures, pages


def compare_figure(old_png, new_png):
    """Compare a previous figure with a fresh one.

    Parameters
    ----------
    old_png, new_png : bytes
        PNG files (any size; decoded to 8-bit RGBA).

    Returns
    -------
    verdict : {"unchanged", "within tolerance", "changed"}
        ``"unchanged"`` if the bytes are equal; ``"within tolerance"`` if the
        sizes agree and every channel differs by at most
        `CHECK_TOLERANCE_LEVELS` of 255 on at most `CHECK_TOLERANCE_FRACTION`
        of the pixels; else ``"changed"``.
    how : str
        The size change, or the largest per-channel difference (as a fraction
        of full scale) and the number of pixels that differ; empty when unchanged.
    """
    if old_png == new_png:
        return "unchanged", ""
    a, b = _png_pixels(old_png), _png_pixels(new_png)
    if a.shape != b.shape:
        return "changed", f"size {a.shape[1]}x{a.shape[0]} -> {b.shape[1]}x{b.shape[0]}"
    d = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2)
    levels, count = int(d.max()), int(np.count_nonzero(d))
    how = f"max |dI| = {levels / 255:.4f} ({count:,} pixels differ)"
    within = levels <= CHECK_TOLERANCE_LEVELS and count <= CHECK_TOLERANCE_FRACTION * d.size
    return ("within tolerance" if within else "changed"), how


def run(args, out):
    """Do what ``args`` asks, the report into ``out`` (a `renderer.cmdline.Outputs`); return
    0, or 1 when ``--check`` finds a changed figure."""
    import fnmatch
    pages = None
    if args.pages is not None:
        pages = [p.strip() for p in args.pages.split(",") if p.strip()]
        if not pages:
            raise UsageError(f"--pages names no page ({args.pages!r}); give names like s1,s4")
    if args.check is None:
        if not args.out or args.out == "-":
            raise UsageError(f"--out {args.out!r}: give a directory to write the figures into")
        out_dir = Path(args.out)
        if out_dir.exists() and not out_dir.is_dir():
            raise UsageError(f"--out {args.out!r} is not a directory")
        if not out_dir.parent.is_dir():
            raise UsageError(f"--out {args.out!r}: directory {str(out_dir.parent)!r} does not exist")
        pages = _resolve_pages(pages)
        staged = out.stage(_StagedDir(out_dir))
        manifest = _render_figures(staged.path, pages)
        for f in manifest["figures"]:
            print(f"{f['id']:40s} {f['width']:4d}x{f['height']:<4d} {f['sha256'][:16]}", file=out)
        v = manifest["code_version"]
        print(f"wrote {len(manifest['figures'])} figures and manifest.json to {out_dir} "
              f"(code {v['git_commit'] or 'no git'}{' + local changes' if v['git_dirty'] else ''}, "
              f"sources {v['source_sha256'][:16]})", file=out)
        return 0
    old_doc, old, old_pages = _load_manifest(args.check, _known_pages())
    pages = _resolve_pages(old_pages if pages is None else pages)
    old = {fid: f for fid, f in old.items() if f["page"] in pages}    # the pages not run are not compared
    with tempfile.TemporaryDirectory(prefix="symrender-figures-") as tmp:
        tmp = Path(tmp)
        new_doc = _render_figures(tmp, pages)
        new = {f["id"]: f for f in new_doc["figures"]}
        changed = 0
        ignored = lambda fid: any(fnmatch.fnmatchcase(fid, pat) for pat in args.ignore)  # noqa: E731
        for fid in sorted(set(old) | set(new), key=lambda i: (i not in new, i)):
            varies = (old.get(fid) or {}).get("varies") or (new.get(fid) or {}).get("varies")
            tag = " (ignored)" if ignored(fid) else f" ({varies}: varies by run)" if varies else ""
            if fid not in new:
                print(f"removed    {fid}{tag}", file=out)
            elif fid not in old:
                print(f"added      {fid}{tag}", file=out)
            elif old[fid]["sha256"] == new[fid]["sha256"]:
                print(f"unchanged  {fid}", file=out)
                continue
            else:
                verdict, how = compare_figure(_read_figure(args.check, old[fid]),
                                              (tmp / new[fid]["file"]).read_bytes())
                if verdict == "within tolerance":
                    print(f"within tolerance {fid}: {how}", file=out)
                    continue
                print(f"changed    {fid}: {how}{tag}", file=out)
            if not tag:
                changed += 1
    ov, nv = old_doc.get("code_version", {}), new_doc["code_version"]
    commit = lambda c: (c or "no git")[:12]  # noqa: E731
    print(f"code: previous {commit(ov.get('git_commit'))} sources {str(ov.get('source_sha256'))[:16]}; "
          f"now {commit(nv['git_commit'])}{' + local changes' if nv['git_dirty'] else ''} "
          f"sources {nv['source_sha256'][:16]}", file=out)
    print(f"{changed} figure(s) changed" if changed else "no figure changed", file=out)
    return 1 if changed else 0


def _command(argv, outputs):
    p = cmdline.Parser(prog="check_figures.py", description=__doc__.split("\n\n")[1])
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--out", metavar="DIR", help="directory to write the figures and manifest.json into")
    what.add_argument("--check", metavar="DIR", help="a previous --out directory to compare a fresh run with")
    p.add_argument("--pages", metavar="s1,s4,...", help="only these pages (default: all; --check: the manifest's)")
    p.add_argument("--ignore", action="append", default=[], metavar="ID-PATTERN",
                   help="with --check: report but do not fail on figures matching this pattern; repeatable")
    return run(p.parse_args(argv), outputs)


def main(argv=None) -> int:
    """Run the tool; return 0, 1 (a figure changed), 2 (an error), 130 (SIGINT) or 143
    (SIGTERM), as `renderer.cmdline.main`."""
    return cmdline.main("check_figures", _command, sys.argv[1:] if argv is None else list(argv))


if __name__ == "__main__":
    sys.exit(main())
