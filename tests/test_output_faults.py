"""Nothing written is ever half a file: outputs under every fault.

A full disk (a file-size limit, which fails writes as a full disk does and needs no privilege; and a real full
tmpfs where the tests may mount one), a read-only folder, SIGTERM, SIGINT and SIGKILL during the write, a stop
signal just after it, a 254-byte file name; and the progress lines a log of a render box gets.

Each fault leaves the target whole or absent (the old file intact), no temporary file behind, and one line
``lenslab: error: PATH: ... (REASON)`` with exit status 1, or "interrupted; nothing was written" with 130.
Processes that are signalled say when they have reached the write; no test sleeps in place of waiting.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lenslab.atomic import STALE_AFTER_SECONDS, TEMPORARY_NAME, WriteFailed, atomic_path, remove_stale_temporaries
from lenslab.render.film import ExportError, read_image, write_image
from tests.helpers import run_cli
from tests.test_batch_farm import FOUR_SLOW_SHOTS

POSIX_ONLY = pytest.mark.skipif(os.name != "posix", reason="POSIX signals, file-size limits and mounts")
SUBPROCESS_SECONDS = 180
SMALL = ["--spp", "1", "--width", "16", "--height", "16"]


def noise(width=64, height=48, seed=0) -> np.ndarray:
    """Linear pixels that no format compresses much: the file's size is known to be about its pixels'."""
    return np.random.default_rng(seed).random((height, width, 3), dtype=np.float32)


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# -- a full disk, simulated: a file-size limit fails writes past it as a full disk does -------------------------
@contextlib.contextmanager
def file_size_limit(limit_bytes: int):
    """Writes in this process fail with EFBIG ("File too large") past ``limit_bytes`` (Python ignores SIGXFSZ)."""
    resource = pytest.importorskip("resource")
    if signal.getsignal(signal.SIGXFSZ) != signal.SIG_IGN:
        pytest.skip("SIGXFSZ is not ignored here: a write past the limit would kill the test process")
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))


@POSIX_ONLY
@pytest.mark.parametrize("suffix", [".png", ".exr", ".tif", ".jpg"])
@pytest.mark.parametrize("limit", [0, 16384], ids=["nothing-fits", "part-fits"])
def test_an_image_that_does_not_fit_is_an_error_and_leaves_the_old_file(tmp_path, suffix, limit):
    """For a JPEG this is also the process surviving: libjpeg, as OpenImageIO sets it up, exits on a failed write."""
    target = tmp_path / f"shot{suffix}"
    write_image(target, noise(8, 8, seed=1))
    old = target.read_bytes()
    # 0 bytes: the library buffers a small image and loses it on close without a word (it was left at 0 bytes).
    # 16 KiB of a 48 KiB PNG: the writer said it succeeded and left a file without its end.
    with file_size_limit(limit), pytest.raises(ExportError) as failure:
        write_image(target, noise(128, 128))
    # libtiff writes its header as it opens the file: with no room at all, opening is what fails.
    step = "open for writing" if (suffix, limit) == (".tif", 0) else "write the image"
    assert str(failure.value) == f"{target}: cannot {step} (File too large)"
    assert leftovers(tmp_path) == [target.name] and target.read_bytes() == old


@POSIX_ONLY
def test_a_scene_that_does_not_fit_is_an_error_naming_it_and_leaves_the_old_file(tmp_path):
    from lenslab.scene.io.loader import open_scene
    from lenslab.scene.io.native import save_scene

    target = tmp_path / "scene.json"
    save_scene(open_scene("cornell_box"), target)
    old = target.read_bytes()
    edited = open_scene("cornell_box")
    edited.camera.f_number = 8.0
    with file_size_limit(len(old) // 2), pytest.raises(OSError) as failure:
        save_scene(edited, target)
    assert str(failure.value) == f"{target}: cannot write (File too large)"
    assert leftovers(tmp_path) == ["scene.json"] and target.read_bytes() == old


def test_a_write_the_disk_refuses_at_the_flush_is_not_renamed_into_place(tmp_path, monkeypatch):
    """fsync is where a network file system or a disk filled under delayed allocation reports writes it had
    accepted: the temporary file is not renamed, and the error names the user's file."""
    import errno

    def refused(fd):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(os, "fsync", refused)
    target = tmp_path / "shot.exr"
    with pytest.raises(WriteFailed) as failure:
        write_image(target, noise(8, 8))
    assert str(failure.value) == f"{target}: cannot write (Input/output error)" and failure.value.errno == errno.EIO
    assert leftovers(tmp_path) == []


class _LibraryThatSaysSo:
    """An OpenImageIO output that writes the file whole but reports a failure, as the library reports some: only in
    its error text (PNG on a full disk), or only from close()."""

    def __init__(self, output, fault: str):
        self.output, self.fault = output, fault

    def open(self, *args):
        return self.output.open(*args)

    def write_image(self, pixels):
        return self.output.write_image(pixels) and self.fault != "write"

    def close(self):
        return self.output.close() and self.fault != "close"

    def geterror(self):
        return "Write error at position 65793, could only write 3839/8192 bytes\nand more"


@pytest.mark.parametrize("fault", ["write", "close", "error-text-only"])
def test_a_failure_the_image_library_reports_is_a_failure_however_it_reports_it(tmp_path, monkeypatch, fault):
    import OpenImageIO as oiio

    create = oiio.ImageOutput.create
    monkeypatch.setattr(oiio.ImageOutput, "create", staticmethod(lambda name: _LibraryThatSaysSo(create(name), fault)))
    with pytest.raises(ExportError) as failure:
        write_image(tmp_path / "shot.png", noise(8, 8))
    # The disk has room now, so the system gives no reason: the library's first line is the reason.
    assert str(failure.value) == (f"{tmp_path / 'shot.png'}: cannot write the image (Write error at position 65793, "
                                  "could only write 3839/8192 bytes)")
    assert leftovers(tmp_path) == []


def lenslab_process(tmp_path: Path, argv: list[str], prelude: str = "", **popen) -> subprocess.Popen:
    """``lenslab ARGV`` as its own process (main() without argv: the process's command, owning its signals),
    after ``prelude``: Python that sets up a fault. Its signals start as a terminal's command's would, whatever
    this test process was started with (a shell's background job ignores SIGINT)."""
    script = "\n".join(["import os, signal, sys", "signal.signal(signal.SIGINT, signal.default_int_handler)",
                        "signal.signal(signal.SIGTERM, signal.SIG_DFL)", prelude, "from lenslab.cli import main",
                        f"sys.argv = ['lenslab', *{[str(a) for a in argv]!r}]", "sys.exit(main())"])
    return subprocess.Popen([sys.executable, "-c", script], cwd=tmp_path, text=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, **popen)


def finish(process: subprocess.Popen) -> tuple[int, str, str]:
    out, err = process.communicate(timeout=SUBPROCESS_SECONDS)
    return process.returncode, out, err


@POSIX_ONLY
@pytest.mark.gl
@pytest.mark.parametrize("suffix", [".png", ".exr"])
@pytest.mark.parametrize("limit, size", [(0, 16), (4096, 128)], ids=["nothing-fits", "part-fits"])
def test_the_command_on_a_full_disk_says_so_in_one_line_and_exits_1(renderer, tmp_path, suffix, limit, size):
    out = tmp_path / f"shot{suffix}"
    prelude = f"import resource; resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, resource.RLIM_INFINITY))"
    status, _, err = finish(lenslab_process(tmp_path, ["cornell_box", "--headless", "-o", out, "--spp", "1",
                                                       "--width", size, "--height", size], prelude))
    assert (status, err) == (1, f"lenslab: error: {out}: cannot write the image (File too large)\n")
    assert leftovers(tmp_path) == []


# -- a full disk and a read-only folder, for real: a small tmpfs, where the tests may mount one -----------------
@contextlib.contextmanager
def mounted_tmpfs(folder: Path, size_bytes: int):
    if os.name != "posix" or os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a tmpfs needs root")
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size_bytes}", "tmpfs", str(folder)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


def fill(folder: Path, leave_bytes: int = 0) -> Path:
    """Fill ``folder``'s file system, then free ``leave_bytes`` of it again."""
    filler = folder / "filler"
    with open(filler, "wb", buffering=0) as file, contextlib.suppress(OSError):  # ENOSPC: full
        while True:
            file.write(bytes(1 << 12))
    if leave_bytes:
        os.truncate(filler, max(0, filler.stat().st_size - leave_bytes))
    return filler


@pytest.mark.gl
@pytest.mark.parametrize("suffix", [".png", ".exr"])
def test_a_completely_full_disk_writes_nothing_and_says_why(renderer, tmp_path, capsys, suffix):
    with mounted_tmpfs(tmp_path / "disk", 64 << 10) as disk:
        fill(disk)
        out = disk / f"tiny{suffix}"
        status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, *SMALL)
        assert (status, err) == (1, f"lenslab: error: {out}: cannot write the image (No space left on device)\n")
        assert leftovers(disk) == ["filler"]


@pytest.mark.gl
def test_a_disk_that_fills_mid_write_keeps_the_old_image(renderer, tmp_path, capsys):
    args = ["cornell_box", "--headless", "--spp", "1", "--width", "256", "--height", "256"]
    assert run_cli(capsys, *args, "-o", tmp_path / "elsewhere.png")[0] == 0
    size = (tmp_path / "elsewhere.png").stat().st_size
    with mounted_tmpfs(tmp_path / "disk", 4 * size) as disk:
        out = disk / "shot.png"
        assert run_cli(capsys, *args, "-o", out, "--seed", "1")[0] == 0
        old = out.read_bytes()
        fill(disk, leave_bytes=size // 2)  # room for half of the new image
        status, err = run_cli(capsys, *args, "-o", out, "--seed", "2")
        assert (status, err) == (1, f"lenslab: error: {out}: cannot write the image (No space left on device)\n")
        assert leftovers(disk) == ["filler", "shot.png"] and out.read_bytes() == old


@contextlib.contextmanager
def read_only_folder(tmp_path: Path):
    """A folder no write can reach: a read-only tmpfs for root (whom permissions do not stop), else mode 0555.
    It holds old.png."""
    if os.name == "posix" and os.geteuid() == 0:
        with mounted_tmpfs(tmp_path / "locked", 1 << 20) as folder:
            write_image(folder / "old.png", noise(8, 8))
            subprocess.run(["mount", "-o", "remount,ro", str(folder)], check=True)
            yield folder
    else:
        folder = tmp_path / "locked"
        folder.mkdir()
        write_image(folder / "old.png", noise(8, 8))
        folder.chmod(0o555)
        try:
            yield folder
        finally:
            folder.chmod(0o755)


@pytest.mark.gl
def test_a_read_only_folder_is_one_line_and_keeps_its_files(renderer, tmp_path, capsys):
    with read_only_folder(tmp_path) as folder:
        old = (folder / "old.png").read_bytes()
        status, err = run_cli(capsys, "cornell_box", "--headless", "-o", folder / "old.png", *SMALL)
        assert status == 1 and err.count("\n") == 1 and err.startswith(f"lenslab: error: {folder / 'old.png'}: ")
        assert "not writable" in err
        # Past the command line's own check, the writers say the same, naming the file and the reason.
        with pytest.raises(WriteFailed, match=re.escape(f"{folder / 'new.exr'}: cannot write in {folder} (")):
            write_image(folder / "new.exr", noise(8, 8))
        from lenslab.scene.io.loader import open_scene
        from lenslab.scene.io.native import save_scene

        with pytest.raises(OSError, match=r"(Read-only file system|Permission denied)\)$"):
            save_scene(open_scene("cornell_box"), folder / "scene.json")
        assert leftovers(folder) == ["old.png"] and (folder / "old.png").read_bytes() == old


# -- names --------------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_a_254_byte_output_name_is_written(renderer, tmp_path, capsys):
    out = tmp_path / ("f" * 250 + ".png")  # 255 bytes is the longest name most file systems allow
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, *SMALL)
    assert status == 0, err
    assert read_image(out)[0].shape == (16, 16, 3) and leftovers(tmp_path) == [out.name]


def test_temporary_files_are_short_named_ours_and_keep_the_format_suffix(tmp_path):
    for name in ("f" * 250 + ".exr", "scene.json", "no_suffix", "odd.suffix-with-dash"):
        with atomic_path(tmp_path / name) as tmp:
            assert tmp.parent == tmp_path and tmp.name.startswith(".lenslab-") and len(tmp.name) < 60
            assert TEMPORARY_NAME.fullmatch(tmp.name), tmp.name
            assert tmp.name.endswith(".tmp" + (Path(name).suffix if name.endswith((".exr", ".json")) else ""))
            tmp.write_text("whole")
        assert (tmp_path / name).read_text() == "whole"
    assert len(leftovers(tmp_path)) == 4


# -- stale temporaries --------------------------------------------------------------------------------------------
def a_dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def our_temporary(folder: Path, pid: int, host: str | None = None, age_seconds: float = 0.0) -> Path:
    from lenslab.atomic import _host_tag

    path = folder / f".lenslab-{pid}-{host or _host_tag()}-abc123de.tmp.png"
    path.write_bytes(b"half an image")
    if age_seconds:
        then = time.time() - age_seconds
        os.utime(path, (then, then))
    return path


@POSIX_ONLY
def test_only_our_temporaries_whose_writer_is_gone_are_swept(tmp_path):
    dead = a_dead_pid()
    removed = {
        our_temporary(tmp_path, dead),  # its writer was killed
        our_temporary(tmp_path, os.getpid()),  # by an earlier process of our number (a container's pid 1, say)
        our_temporary(tmp_path, os.getppid(), host="0f0f0f", age_seconds=STALE_AFTER_SECONDS + 60),  # anyone's, old
    }
    kept = {
        our_temporary(tmp_path, os.getppid()),  # a live process's: a write under way
        our_temporary(tmp_path, dead, host="0f0f0f"),  # another machine's, of a shared folder: we cannot ask
    }
    for name in (".lenslab-notes.txt", ".shot.k2j3h4g5.png", f".lenslab-{dead}.png", "shot.png",
                 f".lenslab-{dead}-abcdef-abc123de.tmp.png.bak"):  # not named as ours: never touched
        (tmp_path / name).write_text("someone's")
        os.utime(tmp_path / name, (0, 0))
        kept.add(tmp_path / name)
    (tmp_path / f".lenslab-{dead}-abcdef-0000.tmp.png").mkdir()  # a folder: not a file we wrote
    kept.add(tmp_path / f".lenslab-{dead}-abcdef-0000.tmp.png")
    assert all(p.exists() for p in removed)
    with atomic_path(tmp_path / "shot.png") as underway:  # a write sweeps its folder first
        assert {p for p in tmp_path.iterdir()} == kept | {underway}
        assert remove_stale_temporaries(tmp_path) == []  # and is not swept itself while under way
        underway.write_bytes(b"whole")
    assert {p for p in tmp_path.iterdir()} == kept | {tmp_path / "shot.png"}


# -- signals -------------------------------------------------------------------------------------------------------
#: Python for a process to run first: its image writer announces the temporary file it has written, then waits
#: on stdin, so that a test signals it mid-write.
BLOCKED_WRITER = """
from lenslab.render import film
encode = film._encode
def encode_then_wait(tmp, *args):
    encode(tmp, *args)
    print(tmp, flush=True)
    sys.stdin.read()
film._encode = encode_then_wait
"""


def temporary_file_announced(process: subprocess.Popen) -> Path:
    ready, _, _ = select.select([process.stdout], [], [], SUBPROCESS_SECONDS)
    line = process.stdout.readline() if ready else ""
    if not line:
        process.kill()
        pytest.fail(f"the render never reached its write: {process.communicate()[1]}")
    return Path(line.strip())


@POSIX_ONLY
@pytest.mark.gl
@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_stop_signal_during_the_write_removes_the_temporary_file(renderer, tmp_path, stop):
    out = tmp_path / "shot.exr"
    process = lenslab_process(tmp_path, ["cornell_box", "--headless", "-o", out, *SMALL], BLOCKED_WRITER,
                              stdin=subprocess.PIPE)
    temporary = temporary_file_announced(process)
    assert temporary.is_file() and temporary.parent == tmp_path  # written, not yet renamed
    process.send_signal(stop)
    status, _, err = finish(process)
    assert (status, err) == (130, "lenslab: interrupted; nothing was written\n")
    assert leftovers(tmp_path) == []


@POSIX_ONLY
@pytest.mark.gl
def test_what_a_killed_writer_leaves_is_swept_by_the_next_write(renderer, tmp_path, capsys):
    out = tmp_path / "shot.png"
    process = lenslab_process(tmp_path, ["cornell_box", "--headless", "-o", out, *SMALL], BLOCKED_WRITER,
                              stdin=subprocess.PIPE)
    temporary = temporary_file_announced(process)
    process.kill()  # SIGKILL: no clean-up runs
    finish(process)
    assert leftovers(tmp_path) == [temporary.name] and TEMPORARY_NAME.fullmatch(temporary.name)
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "next.png", *SMALL)
    assert status == 0, err
    assert leftovers(tmp_path) == ["next.png"]


#: A stop signal at each moment after the image takes its name: as the rename returns, as the GPU is released,
#: and as the process exits (an atexit function runs after main() has returned).
LATE_SIGNALS = """
import atexit
from lenslab.atomic import os as atomic_os
from lenslab.render.job import RenderJob
replace, release = atomic_os.replace, RenderJob.release
def replace_then_stop(*args):
    replace(*args)
    signal.raise_signal({stop})
def stop_then_release(self):
    signal.raise_signal({stop})
    release(self)
atomic_os.replace, RenderJob.release = replace_then_stop, stop_then_release
atexit.register(signal.raise_signal, {stop})
"""


@POSIX_ONLY
@pytest.mark.gl
@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_stop_signal_after_the_image_is_in_place_is_ignored(renderer, tmp_path, stop):
    out = tmp_path / "shot.png"
    process = lenslab_process(tmp_path, ["cornell_box", "--headless", "-o", out, *SMALL],
                              LATE_SIGNALS.format(stop=int(stop)))
    status, _, err = finish(process)
    assert status == 0 and re.fullmatch(rf"wrote {re.escape(str(out))} \(16x16, 1 spp, [0-9.]+ s\)\n", err), err
    assert read_image(out)[0].shape == (16, 16, 3) and leftovers(tmp_path) == ["shot.png"]


@pytest.mark.gl
def test_a_command_called_in_process_leaves_the_callers_signal_handlers_alone(renderer, tmp_path, capsys):
    before = {stop: signal.getsignal(stop) for stop in (signal.SIGINT, signal.SIGTERM)}
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", *SMALL)
    assert status == 0, err
    assert {stop: signal.getsignal(stop) for stop in before} == before


@pytest.mark.slow
@POSIX_ONLY
@pytest.mark.gl
def test_a_batch_stopped_by_sigterm_keeps_its_written_shots_and_says_so(renderer, tmp_path):
    (tmp_path / "shots.toml").write_text(FOUR_SLOW_SHOTS)
    batch = subprocess.Popen([sys.executable, "-m", "lenslab", "batch", "shots.toml", "--workers", "1"], cwd=tmp_path,
                             stderr=subprocess.PIPE, text=True)
    first = None
    for line in batch.stderr:
        if line.startswith("wrote "):
            first = Path(line.split()[1]).name
            batch.send_signal(signal.SIGTERM)  # to the batch alone, as a service manager or a farm's time-out sends it
            break
    rest = batch.stderr.read()
    assert batch.wait(timeout=SUBPROCESS_SECONDS) == 130, rest
    assert rest.startswith("lenslab batch: interrupted; every shot reported done is written") and rest.count("\n") == 1
    images = [name for name in leftovers(tmp_path) if name != "shots.toml"]
    assert first in images and len(images) < 4 and all(name.endswith(".exr") for name in images)  # no temporary


# -- a log of a render box -----------------------------------------------------------------------------------------
def test_progress_lines_come_every_so_often_with_samples_time_and_speed():
    from lenslab.cli import _progress_lines
    from lenslab.render.job import JobProgress

    printed = []
    report = _progress_lines(10.0)
    with contextlib.redirect_stderr(_Lines(printed)):
        for elapsed in (0.5, 4.0, 10.2, 12.0, 19.9, 20.3, 31.0):
            report(JobProgress(int(elapsed), 64, elapsed, None, 2.5e6))
        _progress_lines(10.0)(JobProgress(3, None, 10.0, 60.0, 1e5))
    assert printed == ["lenslab: rendering: 10 of 64 spp after 10 s (2.50 M samples/s)",
                       "lenslab: rendering: 20 of 64 spp after 20 s (2.50 M samples/s)",
                       "lenslab: rendering: 31 of 64 spp after 31 s (2.50 M samples/s)",
                       "lenslab: rendering: 3 spp after 10 of 60 s (0.10 M samples/s)"]


class _Lines:
    def __init__(self, lines: list[str]):
        self.lines = lines

    def write(self, text: str) -> None:
        self.lines.extend(line for line in text.splitlines() if line)

    def flush(self) -> None:
        pass


@pytest.mark.gl
def test_a_render_logged_to_a_file_prints_progress_lines(renderer, tmp_path, capsys, monkeypatch):
    import lenslab.cli

    args = ["cornell_box", "--headless", "-o", tmp_path / "x.png", "--spp", "3", "--width", "16", "--height", "16"]
    status, err = run_cli(capsys, *args)  # stderr is not a terminal here: a log
    assert status == 0 and "rendering:" not in err and "loaded:" not in err  # shorter than the interval: no line
    monkeypatch.setattr(lenslab.cli, "PROGRESS_LINE_SECONDS", 0.0)
    status, err = run_cli(capsys, *args)
    lines = err.splitlines()
    assert status == 0 and lines[-1].startswith("wrote ")
    assert re.fullmatch(r"lenslab: loaded: 36 triangles, 0 spheres; kd-tree of \d+ nodes built in [0-9.]+ s; "
                        r"mesh files read in [0-9.]+ s, placed in [0-9.]+ s, packed in [0-9.]+ s, uploaded in [0-9.]+ s, "
                        r"kernel ready in [0-9.]+ s; ready to sample after [0-9.]+ s", lines.pop(0)), err
    assert lines[:-1] and all(re.fullmatch(r"lenslab: rendering: [0-3] of 3 spp after \d+ s \([0-9.]+ M samples/s\)",
                                           line) for line in lines[:-1]), err


@pytest.mark.gl
def test_a_time_limit_up_before_the_first_pass_says_so_at_once(renderer, tmp_path, capsys, monkeypatch):
    import lenslab.cli

    import lenslab.render.job

    # Many dispatches to one pass, and a report after each: the pass outlasts the first report, as a large
    # image's does at the default slices.
    monkeypatch.setattr(lenslab.render.job, "OFFLINE_DISPATCH_SECONDS", 1e-4)
    monkeypatch.setattr(lenslab.render.job, "REPORT_SECONDS", 1e-4)
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "--width", "256", "--height",
                          "256", "--time-limit", "0.001")
    lines = err.splitlines()
    notice = [i for i, line in enumerate(lines) if "is up before every pixel has a sample" in line]
    assert status == 0 and len(notice) == 1, err
    assert lines[notice[0]] == ("lenslab: warning: the time limit (0.001 s) is up before every pixel has a sample: "
                                "finishing the first pass (65,536 samples) before stopping")
    assert "the first pass was finished" in lines[notice[0] + 1] and lines[-1].startswith("wrote ")


# -- what is at the output's name ------------------------------------------------------------------------------
@pytest.mark.gl
def test_an_output_that_is_a_named_pipe_is_refused_and_left_as_it_is(renderer, tmp_path, capsys):
    """-o onto a named pipe once replaced it with the image (the rename does not ask what it replaces)."""
    import stat

    pipe = tmp_path / "out.png"
    os.mkfifo(pipe)
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", pipe, *SMALL)
    assert status == 1 and err == (f"lenslab: error: {pipe}: a named pipe (FIFO), not a regular file: LensLab writes "
                                   "only where no file is or over a regular file (name another output)\n")
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode) and leftovers(tmp_path) == ["out.png"]
    with pytest.raises(WriteFailed, match="a named pipe"):  # the writers themselves refuse it too
        write_image(pipe, noise(8, 8))
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode)


def test_a_device_node_or_a_folder_is_no_output(tmp_path):
    from lenslab.atomic import check_output_file, check_output_folder

    with pytest.raises(WriteFailed, match=r"^/dev/null: a character device, not a regular file"):
        check_output_folder("/dev/null")  # refused before anything is made in /dev
    with pytest.raises(WriteFailed, match=r": a folder, not a regular file"):
        check_output_file(tmp_path)
    check_output_file(tmp_path / "absent.png")  # nothing there, or a file: the write may go ahead
    (tmp_path / "old.png").write_bytes(b"old")
    check_output_file(tmp_path / "old.png")
