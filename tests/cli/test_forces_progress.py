"""`rigidlcp forces` shows its stages on stderr (it ran 12-18 s silent), none with
--no-progress; the summary on stdout is the same either way."""

from rigidlcp.cli.main import main


def test_forces_progress_names_its_stages_on_stderr(tmp_path, capsys):
    args = ["forces", "--lx", "3", "--ly", "2", "--networks", "1"]
    assert main(args + ["--out", str(tmp_path / "a"), "--json"]) == 0
    shown = capsys.readouterr()
    for stage in ("event LCP", "force ranges", "certify networks", "figures"):
        assert stage in shown.err, stage
    assert main(args + ["--out", str(tmp_path / "b"), "--json", "--no-progress"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == ""
    assert (tmp_path / "a" / "forces.json").exists() and (tmp_path / "b" / "forces.json").exists()
    strip = [line for line in shown.out.splitlines() if '"png"' not in line and "/a/" not in line]
    same = [line for line in quiet.out.splitlines() if '"png"' not in line and "/b/" not in line]
    assert strip == same
