"""What a new user tripped on with a packing made by numpy or a spreadsheet (session 30):
numpy.savetxt's `header=` is written as a comment ("# x,y,r"), and the refusal named the first
data line without saying why the header was not seen; a CSV saved as "UTF-8" by a spreadsheet
starts with a byte-order mark, and its header was refused as "missing x"."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from rigidlcp.cli import main

#: Three unit disks, the top one on the two others (docs/packings.md's three.csv).
THREE = np.array([[1.0, 1.0, 1.0], [3.0, 1.0, 1.0], [2.0, 1.0 + math.sqrt(3.0), 1.0]])


def _one_line_error(capsys, command: str) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rigidlcp {command}: error: ") and "\n" not in err
    return err


def _forceset_json(path, capsys) -> dict:
    assert main(["forceset", str(path), "--no-ranges", "--json", "--no-progress"]) == 0
    return json.loads(capsys.readouterr().out)


def test_numpy_savetxt_header_is_named_as_a_comment(tmp_path, capsys):
    """np.savetxt(..., header="x,y,r") writes "# x,y,r": refused (a comment is not the header:
    the CSV format is unchanged), with one line saying that line 1 names the columns but is a
    comment, and how numpy writes it without the '#'."""
    path = tmp_path / "np.csv"
    np.savetxt(path, THREE, delimiter=",", header="x,y,r")
    assert path.read_text().startswith("# x,y,r")
    assert main(["forceset", str(path), "--no-ranges"]) == 2
    err = _one_line_error(capsys, "forceset")
    assert "line 1 names them but is a comment" in err and "comments=''" in err
    # as the message says: the same data with comments="" is read
    good = tmp_path / "np_ok.csv"
    np.savetxt(good, THREE, delimiter=",", header="x,y,r", comments="")
    out = _forceset_json(good, capsys)
    assert out["exists"] is True and out["c"] == 7  # 2 plane, 2 walls (tight box), 3 pairs


def test_a_byte_order_mark_is_not_part_of_the_header(tmp_path, capsys):
    """A spreadsheet's "CSV UTF-8" starts with U+FEFF: the file reads as the same file
    without it (same disks, contacts and answer)."""
    text = "x,y,r\n" + "".join(f"{x!r},{y!r},{r!r}\n" for x, y, r in THREE.tolist())
    plain, marked = tmp_path / "plain.csv", tmp_path / "bom.csv"
    plain.write_text(text, encoding="utf-8")
    marked.write_text(text, encoding="utf-8-sig")
    assert marked.read_bytes()[:3] == b"\xef\xbb\xbf"
    assert _forceset_json(marked, capsys) == _forceset_json(plain, capsys)


def test_pandas_to_csv_with_its_index_column_is_read(tmp_path, capsys):
    """pandas' `df.to_csv(path)` writes an unnamed index column first (",x,y,r"): other
    columns are ignored, so the file is the packing (written here as pandas writes it)."""
    path = tmp_path / "pd.csv"
    path.write_text(",x,y,r\n" + "".join(f"{k},{x!r},{y!r},{r!r}\n"
                                          for k, (x, y, r) in enumerate(THREE.tolist())))
    out = _forceset_json(path, capsys)
    assert out["p"] == 3 and out["c"] == 7 and out["exists"] is True


def test_bench_problems_names_what_a_folder_problem_is_called(tmp_path, capsys):
    """A folder's problems are named FOLDER/FILE: `--problems p0` (the file's stem, as a user
    types it after `ls`) was refused without a name to use; now the message offers it, and
    nothing is written."""
    from rigidlcp import lcp

    folder = tmp_path / "mine"
    folder.mkdir()
    for k in range(2):
        lcp.LCP(np.eye(2) * (k + 1), np.array([-1.0, 1.0])).save(folder / f"p{k}.npz")
    out = tmp_path / "out"
    argv = ["bench", "--set", str(folder), "--methods", "lemke", "--out", str(out)]
    assert main(argv + ["--problems", "p0.npz"]) == 2
    assert _one_line_error(capsys, "bench").endswith("(did you mean mine/p0?)")
    assert main(argv + ["--problems", "zzz"]) == 2
    assert "problems are named like mine/p0, mine/p1" in _one_line_error(capsys, "bench")
    assert not out.exists()


def test_a_contact_lost_to_rounding_is_named_as_a_near_miss(tmp_path, capsys):
    """Coordinates written with 6 decimals (numpy's fmt="%.6f"): the top disk's height
    2.732051 for 1 + sqrt(3) leaves it 1.7e-7 above its supports, a rattler, and forceset proves
    that such a pile has no equilibrium, which read like physics; the packing line now names
    the near miss and the --gap-tol that makes it a contact, and that tolerance does."""
    path = tmp_path / "rounded.csv"
    np.savetxt(path, THREE, delimiter=",", header="x,y,r", comments="", fmt="%.6f")
    assert main(["forceset", str(path), "--no-ranges", "--no-progress"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert "1 rattler(s)" in first and "near miss(es) of these: disk 2 is 1.7e-07 x radius" in first
    tol = first.split("--gap-tol ")[1].split()[0]
    assert main(["forceset", str(path), "--no-ranges", "--json", "--no-progress",
                 "--gap-tol", tol]) == 0
    fixed = json.loads(capsys.readouterr().out)
    assert fixed["c"] == 7 and fixed["exists"] is True and fixed["packing"]["rattlers"] == []


@pytest.mark.parametrize("command", ["pack", "bench", "forces"])
def test_seed_help_states_its_default(command, capsys):
    """`rigidlcp pack --n 10 --out a.csv` silently used seed 0: --help now says so."""
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert re.search(r"--seed SEED [^-]*\(default 0\)", text)


@pytest.mark.parametrize("command, given", [("simulate", ["--lattice", "rect"]),
                                            ("timestep", ["--ly", "4"]),
                                            ("nullspace", ["--lx", "4"])])
def test_packing_refuses_array_options_given_at_their_default(command, given, tmp_path,
                                                              capsys):
    """`--packing FILE --lattice rect` was taken (rect being the default) and --lattice
    ignored, while another value was refused: an option given is now refused whatever its
    value (docs/usage.md: "given with them it is refused")."""
    path = tmp_path / "three.csv"
    np.savetxt(path, THREE, delimiter=",", header="x,y,r", comments="")
    assert main([command, "--packing", str(path), *given, "--out" if command != "nullspace"
                 else "--json", *([str(tmp_path / "run.npz")] if command != "nullspace"
                                  else [])]) == 2
    assert "give one or the other" in _one_line_error(capsys, command)


@pytest.mark.parametrize("command", ["solve", "certify"])
def test_a_packing_given_to_solve_is_named_as_one(command, tmp_path, capsys):
    """`rigidlcp solve pile.csv` said only that no Siconos header fits."""
    path = tmp_path / "pile.csv"
    np.savetxt(path, THREE, delimiter=",", header="x,y,r", comments="")
    assert main([command, str(path)]) == 2
    err = _one_line_error(capsys, command)
    assert "no Siconos header fits" in err and "looks like a packing of disks" in err
    assert "rigidlcp forceset FILE" in err
