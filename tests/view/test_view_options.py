"""--mcap and --foxglove on the command line: the hardware install does without the view's libraries (one
line, exit 2, when asked for without them), and a log that cannot be written never stops a walk."""

import subprocess
import sys

import pytest

from gaitbot.app.view_options import open_view
from gaitbot.errors import UserError
from helpers import REPO_ROOT, run_cli


def test_a_walk_without_the_options_imports_none_of_the_view():
    code = ("import sys; from gaitbot.app.cli import main; "
            "status = main(['walk', '--robot', 'xl430-biped', '--dry-run', '--distance', '0.1']); "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('mcap', 'mcap_ros2', 'foxglove', 'websockets')"
            " or m.startswith('gaitbot.view'))); sys.exit(status)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO_ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize("missing, flag", [("mcap", "--mcap"), ("mcap_ros2", "--mcap"), ("foxglove", "--foxglove")])
def test_missing_extra_is_one_line(missing, flag, monkeypatch, tmp_path):
    for name in [m for m in sys.modules if m == missing or m.startswith(missing + ".")] + [missing]:
        monkeypatch.setitem(sys.modules, name, None)  # an import of it fails as if it were not installed
    from gaitbot.view import ros2_messages
    ros2_messages.encoder.cache_clear()  # encoders built by earlier tests would hide the missing library
    args = type("Args", (), {"mcap": str(tmp_path / "w.mcap") if flag == "--mcap" else None,
                             "foxglove": ("127.0.0.1", 0) if flag == "--foxglove" else None})()
    from helpers import config
    with pytest.raises(UserError, match=r"needs pip install 'gaitbot\[view\]'"):
        open_view(args, config("op3"), None)


def test_a_full_disk_stops_the_log_not_the_walk(capsys, monkeypatch, tmp_path):
    """The disk fills up after the log has started (outputs must be regular files, so /dev/full is refused up
    front): every write from the 50th on fails as a full disk does, with ENOSPC."""
    import errno

    from gaitbot.view.mcap_log import McapSink

    write, calls = McapSink.write, {"n": 0}

    def filling(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] >= 50:
            raise OSError(errno.ENOSPC, "No space left on device")
        return write(self, *args, **kwargs)

    monkeypatch.setattr(McapSink, "write", filling)
    log = tmp_path / "w.mcap"
    code, out, err = run_cli(capsys, "walk", "--robot", "op3", "--dry-run", "--distance", "0.3", "--mcap", str(log))
    assert code == 0 and "Walk completed" in out
    assert f"note: --mcap {log} stopped at" in err and "No space left on device" in err


@pytest.mark.parametrize("argv, says", [
    (("--mcap", "/no/such/dir/w.mcap"), "argument --mcap: /no/such/dir/w.mcap: cannot write there"),
    (("--foxglove", "host:70000"), "argument --foxglove: expected [HOST:]PORT"),
    (("--mcap", ""), "argument --mcap: empty file name"),
    (("--mcap", "x" * 5000), "argument --mcap: cannot write there (File name too long)")])
def test_bad_options_are_refused_before_anything(argv, says, capsys):
    with pytest.raises(SystemExit) as exit_:  # argparse: the usage error, before the robot is even loaded
        run_cli(capsys, "walk", "--robot", "op3", "--dry-run", "--distance", "0.1", *argv)
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and says in err and len(err.strip().splitlines()) == 1
