"""`rigidlcp forceset` end to end: the fixed JSON interface, --out, refusals."""

import json

from rigidlcp.cli.main import main


def test_forceset_json_interface(tmp_path, capsys):
    f = tmp_path / "p.csv"
    f.write_text("# box: left=0.0 right=4.0\nx,y,r\n1,1,1\n3,1,1\n2,2.7320508075688772,1\n")
    code = main(["forceset", str(f), "--mu-pp", "0", "--mu-plane", "0", "--mu-wall", "0",
                 "--json"])
    d = json.loads(capsys.readouterr().out)
    assert code == 0 and d["exists"] is True and d["dimension"] == 1
    assert d["box"] == {"left": 0.0, "right": 4.0, "plane": 0.0}
    pair = next(c for c in d["contacts"] if (c["i"], c["j"]) == (0, 1))
    assert abs(pair["R"][0]) < 1e-9 and pair["R"][1] is None  # the pyramid's free pair force
    assert {c["j"] for c in d["contacts"]} == {-1, -2, -3, 1, 2}
    out = tmp_path / "out"
    assert main(["forceset", str(f), "--out", str(out), "--no-progress"]) == 0
    assert "dimension" in capsys.readouterr().out
    assert json.loads((out / "forceset.json").read_text())["exists"] is not None
    assert (out / "forceset.png").stat().st_size > 1000 or not json.loads(
        (out / "forceset.json").read_text())["exists"]


def test_forceset_refuses_bad_files(tmp_path, capsys):
    f = tmp_path / "bad.csv"
    f.write_text("x,y,r\n1,1,1\n1.5,1,1\n")
    assert main(["forceset", str(f), "--json"]) == 2
    assert "disks 0 and 1 overlap by 1.5" in capsys.readouterr().err
    f.write_text("x,y,r\n1,1,one\n")
    assert main(["forceset", str(f), "--out", str(tmp_path / "o")]) == 2
    assert "line 2, field 'r'" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
