"""Built kd-trees kept on disk, so that opening a large scene again skips the build.

A million triangles take four seconds to build into a kd-tree on two cores (docs/performance.md), every time the
scene is opened: each shot of a batch on a render box, each reopening in the studio, each undo back to a
geometry seen before. The tree depends only on the primitives' boxes and triangles, the build's constants and
the builder's own code, so it is kept under a hash of exactly those (as Mesa keeps compiled shaders, and as
production renderers keep acceleration structures in their mesh proxies) and read back in a fraction of the
time. Nothing else about the scene enters the key: a new material or camera finds the same tree.

* Only scenes of at least ``MIN_PRIMITIVES`` primitives use the cache; smaller trees build faster than they hash.
* Where: ``$LENSLAB_KDTREE_CACHE`` (a folder; ``off`` turns the cache off), else ``$XDG_CACHE_HOME/lenslab/kdtrees``
  or ``~/.cache/lenslab/kdtrees``.
* At most ``MAX_CACHE_BYTES`` are kept; the trees used least recently go first.
* A tree the build's reference budget cut short (docs/performance.md, "Bounded work") is used again only where
  today's budget is no smaller than the references it holds, so that it is the tree a build would make now.
* A file that cannot be read (cut short, another version's) is built again and replaced; a folder that cannot
  be written costs only the keeping: the render goes on.
"""

from __future__ import annotations

import functools
import hashlib
import os
import time
import zipfile
from pathlib import Path

import numpy as np

from lenslab.render import bsp
from lenslab.render.bsp import KdTree, build_kdtree, reference_budget
from lenslab.resources import user_cache_dir

MIN_PRIMITIVES = 50_000
MAX_CACHE_BYTES = 2 * 1024**3
_FORMAT = b"lenslab-kdtree-2"
# KdTree's fields stored as numbers beside its arrays (params and build_seconds are handled apart).
_SCALARS = ("max_depth", "max_depth_limit", "node_count", "leaf_count", "empty_leaf_count", "refs_per_prim",
            "sah_cost", "reference_limit", "budget_leaves")


def cache_dir() -> Path | None:
    """The folder trees are kept in, or None where ``LENSLAB_KDTREE_CACHE=off``."""
    chosen = os.environ.get("LENSLAB_KDTREE_CACHE", "")
    if chosen.lower() in ("off", "0", "no", "false"):
        return None
    return Path(chosen) if chosen else user_cache_dir("kdtrees")


@functools.cache
def _builder_fingerprint() -> bytes:
    """The builders' source: any change to how trees are built makes new keys."""
    digest = hashlib.sha256(Path(bsp.__file__).read_bytes())
    digest.update(Path(bsp.__file__).with_name("bsp_compiled.py").read_bytes())
    return digest.digest()


def tree_key(prim_bounds: np.ndarray, triangles: np.ndarray | None, options: dict) -> str:
    digest = hashlib.blake2b(_FORMAT + _builder_fingerprint(), digest_size=20)
    digest.update(repr(sorted(options.items())).encode())
    digest.update(np.ascontiguousarray(prim_bounds, dtype=np.float32).tobytes())
    if triangles is not None:
        digest.update(b"triangles")
        digest.update(np.ascontiguousarray(triangles, dtype=np.float32).tobytes())
    return digest.hexdigest()


def kdtree(prim_bounds: np.ndarray, *, triangles: np.ndarray | None = None, folder: Path | None = None,
           **options) -> KdTree:
    """``build_kdtree(prim_bounds, triangles=triangles, **options)``, from the cache where it holds that tree.

    ``folder``: the cache's folder (default :func:`cache_dir`). The returned tree's ``from_cache`` says which
    it was, and its ``build_seconds`` how long reading it took.
    """
    folder = cache_dir() if folder is None else folder
    prim_count = len(prim_bounds)
    if folder is None or prim_count < MIN_PRIMITIVES or options.get("max_refs") is not None:
        return build_kdtree(prim_bounds, triangles=triangles, **options)
    start = time.perf_counter()
    build_options = {name: value for name, value in options.items() if name not in ("threads", "memory_bytes")}
    path = folder / f"{tree_key(prim_bounds, triangles, build_options)}.npz"
    tree = _read(path, start)
    if tree is not None:
        budget = _budget(prim_count, options)
        if len(tree.prim_refs) <= budget and (tree.budget_leaves == 0 or tree.reference_limit == budget):
            return tree
    tree = build_kdtree(prim_bounds, triangles=triangles, **options)
    _write(path, tree)
    _evict(folder, keep=path)
    return tree


_PARTIAL = ".partial.npz"  # ".<key>.<pid>.partial.npz": a tree being written by process <pid>
#: A partial file this old has lost its writer, wherever that ran: no tree takes an hour to write.
_ORPHANED_AFTER_SECONDS = 3600


def _remove_orphaned_partials(folder: Path) -> None:
    """Remove the partial files of writers that no longer run on this machine, or that are older than any write
    takes (a writer of another machine sharing the folder). Best effort: what cannot be removed stays."""
    now = time.time()
    try:
        partials = [entry for entry in folder.glob(f".*{_PARTIAL}") if entry.is_file()]
    except OSError:
        return
    for entry in partials:
        pid_text = entry.name[: -len(_PARTIAL)].rpartition(".")[2]
        try:
            orphaned = now - entry.stat().st_mtime > _ORPHANED_AFTER_SECONDS
            if not orphaned and pid_text.isdigit() and int(pid_text) != os.getpid():
                try:
                    os.kill(int(pid_text), 0)
                except ProcessLookupError:
                    orphaned = True
                except OSError:  # EPERM: another user's process, alive
                    pass
            if orphaned:
                entry.unlink()
        except OSError:
            continue


def _budget(prim_count: int, options: dict) -> int:
    memory = options.get("memory_bytes")
    return reference_budget(prim_count, memory if memory is not None else bsp.available_memory_bytes())


def _read(path: Path, start: float) -> KdTree | None:
    try:
        with np.load(path, allow_pickle=False) as stored:
            if bytes(stored["format"]) != _FORMAT:
                return None
            scalars = dict(zip(_SCALARS, stored["scalars"].tolist()))
            params = {**dict(zip(stored["int_param_names"].tolist(), stored["int_param_values"].tolist())),
                      **dict(zip(stored["float_param_names"].tolist(), stored["float_param_values"].tolist())),
                      **dict(zip(stored["str_param_names"].tolist(), stored["str_param_values"].tolist()))}
            tree = KdTree(nodes=stored["nodes"], prim_refs=stored["prim_refs"], bounds=stored["bounds"],
                          build_seconds=time.perf_counter() - start, params=params, from_cache=True,
                          **{name: (float(value) if name in ("refs_per_prim", "sah_cost") else int(value))
                             for name, value in scalars.items()})
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile):
        return None  # missing, cut short, or another layout
    try:
        os.utime(path)  # used now: evicted last
    except OSError:
        pass
    return tree


def _write(path: Path, tree: KdTree) -> None:
    """Write atomically (a reader never sees half a file); a folder that cannot be written is skipped. A write
    that fails (a full disk, a quota) or is interrupted takes its partial file with it."""
    partial = path.with_name(f".{path.stem}.{os.getpid()}{_PARTIAL}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        ints = {name: value for name, value in tree.params.items() if isinstance(value, (int, np.integer))}
        texts = {name: value for name, value in tree.params.items() if isinstance(value, str)}
        floats = {name: float(value) for name, value in tree.params.items() if name not in ints and name not in texts}
        np.savez(partial, format=np.frombuffer(_FORMAT, np.uint8), nodes=tree.nodes, prim_refs=tree.prim_refs,
                 bounds=tree.bounds, scalars=np.array([float(getattr(tree, name)) for name in _SCALARS]),
                 int_param_names=np.array(list(ints), dtype=str),
                 int_param_values=np.array(list(ints.values()), np.int64),
                 float_param_names=np.array(list(floats), dtype=str),
                 float_param_values=np.array(list(floats.values()), np.float64),
                 str_param_names=np.array(list(texts), dtype=str), str_param_values=np.array(list(texts.values()), dtype=str))
        os.replace(partial, path)
    except BaseException as exc:
        try:
            partial.unlink(missing_ok=True)
        except OSError:
            pass
        if not isinstance(exc, OSError):
            raise


def _evict(folder: Path, keep: Path) -> None:
    """Delete the least recently used trees until the folder holds at most MAX_CACHE_BYTES, and the partial files
    of writers that are gone (killed mid-write: they ran no clean-up)."""
    _remove_orphaned_partials(folder)
    try:
        files = [(entry, entry.stat()) for entry in folder.glob("*.npz")]
    except OSError:
        return
    total = sum(stat.st_size for _, stat in files)
    for entry, stat in sorted(files, key=lambda item: item[1].st_mtime):
        if total <= MAX_CACHE_BYTES:
            break
        if entry == keep:
            continue
        try:
            entry.unlink()
            total -= stat.st_size
        except OSError:
            pass
