"""lenslab batch on a two-worker Dask LocalCluster (llvmpipe, tiny images): shots are written, a failed shot
does not stop the others, a second run skips what exists, a shot split across workers equals the render of
all its samples on one machine, and a worker killed mid-shot costs a retry, not the batch."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from lenslab.batch.farm import PartRetried, ShotDone, ShotFailed, ShotProgress, ShotSkipped, local_cluster, run_batch
from lenslab.render.film import read_image
from lenslab.scene.overrides import SceneOverrides
from tests.test_batch_spec import batch as write_batch  # writes shots.toml in a folder and reads it

pytestmark = pytest.mark.gl

#: Four shots that each take a few seconds: long enough to interrupt the batch between two of them.
FOUR_SLOW_SHOTS = """
    [[shots]]
    scene = "cornell_box"
    output = "f{f_number}.exr"
    width = 64
    spp = 200
    f_number = [1.4, 2, 2.8, 4]
"""


@pytest.fixture(scope="module")
def client(renderer):  # the renderer fixture skips where there is no GL at all
    from distributed import Client

    with local_cluster(2) as cluster, Client(cluster) as client:
        yield client


@pytest.mark.slow
def test_shots_are_written_a_failure_is_reported_and_a_rerun_skips_them(tmp_path, client):
    (tmp_path / "broken.json").write_text('{"lenslab_scene": 1, "camera": {"f_number": "wide"}}')
    batch = write_batch(tmp_path, """
        [defaults]
        scene = "cornell_box"
        width = 24
        spp = 2
        [[shots]]
        name = "bracket"
        output = "out/f{f_number}.png"
        f_number = [2, 8]
        [[shots]]
        name = "broken"
        scene = "broken.json"
        output = "out/broken.exr"
    """)
    events = []
    summary = run_batch(batch.shots, client, on_event=events.append)
    assert sorted(s.name for s in summary.done) == ["bracket f/2", "bracket f/8"]  # in whatever order they end
    assert [(shot.name, "broken.json:" in message) for shot, message in summary.failed] == [("broken", True)]
    assert (tmp_path / "out/f2.png").is_file() and (tmp_path / "out/f8.png").is_file()
    assert not (tmp_path / "out/broken.exr").exists()
    assert {type(e) for e in events} >= {ShotDone, ShotFailed, ShotProgress}

    written = {p: p.stat().st_mtime_ns for p in (tmp_path / "out").iterdir()}
    again = []
    summary = run_batch(batch.shots, client, on_event=again.append)
    assert sorted(s.name for s in summary.skipped) == ["bracket f/2", "bracket f/8"]
    assert [shot.name for shot, _ in summary.failed] == ["broken"]  # rendered again, since it has no file
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "out").iterdir()} == written
    assert sum(isinstance(e, ShotSkipped) for e in again) == 2


def test_a_shot_split_across_workers_equals_one_render_of_all_its_samples(tmp_path, client, renderer):
    from lenslab.render.job import RenderJob

    batch = write_batch(tmp_path, """
        [[shots]]
        scene = "dof_chart"
        output = "split.exr"
        width = 40
        spp = 12
        seed = 7
        split = 3
    """)
    summary = run_batch(batch.shots, client)
    assert summary.ok
    merged, metadata = read_image(tmp_path / "split.exr")
    assert metadata["lenslab:SamplesPerPixel"] == 12 and metadata["lenslab:RenderParts"] == 3

    shot = batch.shots[0]
    job = RenderJob(renderer, shot.open_scene(), spp=12)
    single = job.run()
    job.release()
    # The same 12 sample indices of the same seed, summed in another order: equal to float rounding, once the
    # file's exposure is taken off (the chart is shot with a camera's physical exposure, which every export applies).
    np.testing.assert_allclose(merged / metadata["lenslab:ExposureScale"], single, rtol=1e-5, atol=1e-6)

    other_seed = RenderJob(renderer, SceneOverrides(seed=8).apply(shot.open_scene()), spp=12)
    different = other_seed.run()
    other_seed.release()
    assert np.abs(different - single).max() > 1e-3  # the comparison above could have failed


def test_a_time_limited_split_renders_disjoint_ranges_and_records_their_total(tmp_path, client):
    batch = write_batch(tmp_path, """
        [[shots]]
        scene = "cornell_box"
        output = "timed.exr"
        width = 16
        time_limit = 0.3
        split = 2
    """)
    summary = run_batch(batch.shots, client)
    assert summary.ok
    image, metadata = read_image(tmp_path / "timed.exr")
    assert metadata["lenslab:RenderParts"] == 2 and metadata["lenslab:SamplesPerPixel"] >= 2
    assert np.isfinite(image).all() and image.mean() > 0


@pytest.mark.slow
def test_a_worker_killed_mid_shot_is_replaced_and_the_batch_completes(tmp_path, renderer):
    from distributed import Client

    batch = write_batch(tmp_path, """
        [[shots]]
        scene = "cornell_box"
        output = "long.exr"
        width = 64
        spp = 600
    """)
    events: list = []
    killed: list[int] = []
    with local_cluster(2) as cluster, Client(cluster) as client:
        pids = client.run(os.getpid)  # worker address: process

        def kill_the_worker_on_first_progress(event):
            events.append(event)
            if isinstance(event, ShotProgress) and not killed:
                killed.append(pids[event.workers[0]])
                os.kill(killed[0], signal.SIGKILL)

        summary = run_batch(batch.shots, client, on_event=kill_the_worker_on_first_progress)
    assert killed and summary.ok, summary.failed
    assert any(isinstance(e, PartRetried) for e in events)
    image, metadata = read_image(tmp_path / "long.exr")
    assert metadata["lenslab:SamplesPerPixel"] == 600 and np.isfinite(image).all() and image.mean() > 0


@pytest.mark.slow
def test_the_command_renders_a_batch_writes_a_contact_sheet_and_exits_1_on_a_failed_shot(tmp_path, renderer):
    (tmp_path / "shots.toml").write_text("""
        contact_sheet = "sheet.png"
        [defaults]
        scene = "cornell_box"
        width = 32
        spp = 2
        [[shots]]
        output = "c_f{f_number}.png"
        f_number = [1.4, 16]
        [[shots]]
        name = "missing"
        scene = "no_such_scene"
        output = "missing.png"
    """)
    run = subprocess.run([sys.executable, "-m", "lenslab", "batch", str(tmp_path / "shots.toml"), "--workers", "2"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 1, run.stderr
    assert "Traceback" not in run.stderr
    assert "wrote " + str(tmp_path / "c_f1.4.png") in run.stderr
    assert "1 of 3 shots failed" in run.stderr and "missing:" in run.stderr
    sheet, _ = read_image(tmp_path / "sheet.png")
    thumbnail, _ = read_image(tmp_path / "c_f1.4.png")
    assert sheet.shape[1] > 2 * 320 and sheet.shape[0] > thumbnail.shape[0]

    dry = subprocess.run([sys.executable, "-m", "lenslab", "batch", str(tmp_path / "shots.toml"), "--dry-run"],
                         capture_output=True, text=True, timeout=60)
    assert dry.returncode == 0 and "exists, skipped" in dry.stdout and "missing: " in dry.stdout


@pytest.mark.slow
def test_the_command_refuses_bad_arguments_in_one_line(tmp_path):
    for args, status, expected in (
        (["--scheduler", "tcp://x:8786", "--workers", "2"], 2, "--scheduler uses the cluster's own workers"),
        (["--workers", "0"], 2, "0 is out of range"),
        (["--devices", "a,b"], 2, "expected device numbers"),
        ([], 1, "no such batch file"),
    ):
        run = subprocess.run([sys.executable, "-m", "lenslab", "batch", str(tmp_path / "none.toml"), *args],
                             capture_output=True, text=True, timeout=60)
        assert run.returncode == status and expected in run.stderr and len(run.stderr.splitlines()) == 1, run.stderr


def test_a_local_worker_leaves_ctrl_c_to_the_batch():
    """A terminal's Ctrl-C reaches the workers too; one that took it would stop and print Dask's traceback."""
    import operator

    from distributed import Client

    with local_cluster(1) as cluster, Client(cluster) as own_client:
        (pid_before,) = own_client.run(os.getpid).values()
        assert list(own_client.run(lambda: signal.getsignal(signal.SIGINT) == signal.SIG_IGN).values()) == [True]
        os.kill(pid_before, signal.SIGINT)
        assert own_client.submit(operator.add, 1, 2, pure=False).result(timeout=60) == 3
        assert list(own_client.run(os.getpid).values()) == [pid_before]  # the same process, not a replacement


@pytest.mark.slow
def test_ctrl_c_keeps_every_finished_shot_and_the_next_run_renders_the_rest(tmp_path, renderer):
    (tmp_path / "shots.toml").write_text(FOUR_SLOW_SHOTS)
    command = [sys.executable, "-m", "lenslab", "batch", str(tmp_path / "shots.toml"), "--workers", "1"]
    # A new session, signalled as a whole: Ctrl-C on a terminal reaches the Dask worker processes too.
    batch = subprocess.Popen(command, stderr=subprocess.PIPE, text=True, start_new_session=True)
    first = ""
    for line in batch.stderr:
        if line.startswith("wrote "):
            first = line.split()[1]
            os.killpg(batch.pid, signal.SIGINT)
            break
    rest = batch.stderr.read()
    assert batch.wait(timeout=120) == 130 and "Traceback" not in rest, rest
    assert "interrupted; every shot reported done is written" in rest
    written = sorted(tmp_path.glob("*.exr"))
    assert str(written[0]) == first and len(written) < 4
    assert not list(tmp_path.glob(".*"))  # no temporary file left behind
    image, metadata = read_image(written[0])
    assert metadata["lenslab:SamplesPerPixel"] == 200 and np.isfinite(image).all()

    again = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"skipped {written[0].stem}" in again.stderr and len(list(tmp_path.glob("*.exr"))) == 4


@pytest.mark.slow
def test_the_command_uses_a_running_cluster(tmp_path, client):
    (tmp_path / "shots.toml").write_text("""
        [[shots]]
        scene = "cornell_box"
        output = "seed{seed}.png"
        width = 16
        spp = 1
        seed = [1, 2, 3]
    """)
    run = subprocess.run([sys.executable, "-m", "lenslab", "batch", str(tmp_path / "shots.toml"),
                          "--scheduler", client.scheduler.address], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["seed1.png", "seed2.png", "seed3.png"]
    unreachable = subprocess.run([sys.executable, "-m", "lenslab", "batch", str(tmp_path / "shots.toml"), "--force",
                                  "--scheduler", "tcp://127.0.0.1:9"], capture_output=True, text=True, timeout=120,
                                 env={**os.environ, "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"})
    assert unreachable.returncode == 1 and "Traceback" not in unreachable.stderr, unreachable.stderr
    assert len(unreachable.stderr.strip().splitlines()) == 1 and "cannot reach a Dask scheduler" in unreachable.stderr


@pytest.mark.parametrize("address", ["ucx://x", "foo://x:8786"])
def test_a_scheduler_address_dask_cannot_connect_over_is_one_usage_line(tmp_path, capsys, address):
    """ucx:// is a protocol Dask knows but cannot use without UCX-Py: its connector could not even be made, and
    the batch ended in a traceback."""
    from lenslab.cli import main

    (tmp_path / "s.toml").write_text('[[shots]]\nscene = "cornell_box"\noutput = "s.png"\n')
    status = main(["batch", str(tmp_path / "s.toml"), "--scheduler", address])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"lenslab batch: error: --scheduler {address}: this installation of Dask cannot connect "
                          "over that protocol (")
    assert "tcp://" in err and not (tmp_path / "s.png").exists()
