"""Packing files (issue 22.2): round trips, the LAMMPS reader, bad files refused by line and
field, and a rectangular array written as a packing file giving the array's event LCPs."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidFile, OutputExists
from rigidlcp.models.deposition import deposit
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, event_problem, initial_state
from rigidlcp.models.packing import Overlap
from rigidlcp.models.packing_io import read_disks, read_packing, write_packing


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_round_trip_exact(tmp_path, suffix):
    lat = deposit(60, seed=3, radii=(0.6, 1.4))
    path = write_packing(tmp_path / f"p{suffix}", lat)
    back = read_packing(path)
    for name in ("x", "radii", "masses", "inertias", "i", "j", "n"):
        assert np.array_equal(getattr(back, name), getattr(lat, name)), name
    assert (back.left, back.right) == (lat.left, lat.right)
    with pytest.raises(OutputExists):
        write_packing(path, lat)


def test_rectangular_file_gives_the_arrays_event_lcps(tmp_path):
    """rect 5x3 (radius 1, m = 1, I = 1/2 = the file's defaults m = r^2, I = m r^2 / 2) read
    back from CSV: the same W, q and event LCPs, exactly, up to the order of the contacts."""
    lat = models.rectangular(5, 3)
    back = read_packing(write_packing(tmp_path / "rect.csv", lat))
    where = {(int(i), int(j)): b for b, (i, j) in enumerate(zip(back.i, back.j))}
    perm = np.array([where[(int(i), int(j))] for i, j in zip(lat.i, lat.j)])
    sa, sb = models.System(lat, gamma=0.1), models.System(back, gamma=0.1)
    rows = np.r_[perm, back.c + perm]
    assert np.array_equal(Dynamics(sb).W[np.ix_(rows, rows)], Dynamics(sa).W)
    st = initial_state(sa, seed=5)
    sp = np.zeros(back.c, dtype=int)
    sp[perm] = st.s
    ea, eb = event_problem(sa, st), event_problem(sb, State(0.0, st.omega, st.V, sp))
    cand = {int(a): k for k, a in enumerate(eb.candidates)}
    kb = np.array([cand[int(perm[a])] for a in ea.candidates], dtype=int)
    z = np.r_[perm, back.c + kb, back.c + eb.k + kb]
    assert np.array_equal(eb.lcp.M[np.ix_(z, z)], ea.lcp.M)
    assert np.array_equal(eb.lcp.q[z], ea.lcp.q)


def test_csv_defaults_and_box(tmp_path):
    f = tmp_path / "a.csv"
    f.write_text("# two disks\nid,r,x,y\n0,1,1,1\n1,2,6,2\n")
    d = read_disks(f)
    assert np.array_equal(d.m, [1.0, 4.0]) and np.array_equal(d.I, [0.5, 8.0])
    assert d.box() == (0.0, 8.0)  # the tight box
    lat = read_packing(f, right="none")
    assert lat.right is None and lat.left == 0.0


LAMMPS = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS ff ff pp
0 4
0 10
-0.5 0.5
ITEM: ATOMS id type x y z radius mass
1 1 1.0 1.0 0 1.0 2.0
2 1 3.0 1.0 0 1.0 2.0
"""


def test_lammps_dump(tmp_path):
    f = tmp_path / "dump.atoms"
    f.write_text(LAMMPS)
    d = read_disks(f)
    assert np.array_equal(d.x, [[1, 1], [3, 1]]) and np.array_equal(d.m, [2, 2])
    lat = read_packing(f)
    assert lat.c == 5  # plane x2, both walls, the pair
    f.write_text(LAMMPS.replace("2 1 3.0 1.0 0 1.0", "2 1 3.0 1.0 0 abc"))
    with pytest.raises(InvalidFile, match=r"line 11, field 'radius': 'abc' is not a number"):
        read_disks(f)


def _dump(tmp_path, box: str | None):
    """LAMMPS with its BOX BOUNDS header and x line replaced (None: no BOX BOUNDS at all)."""
    lines = LAMMPS.splitlines()
    if box is None:
        del lines[4:8]
    else:
        lines[4:6] = box.splitlines()
    f = tmp_path / "dump.atoms"
    f.write_text("\n".join(lines) + "\n")
    return f


def test_lammps_box_bounds_are_the_walls(tmp_path):
    """x's fixed bounds are the walls (here 0 and 6: the right disk does not touch x = 6);
    without BOX BOUNDS or with shrink-wrapped bounds, the tight box (0 and 4)."""
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS ff ff pp\n0 6"))
    assert (lat.left, lat.right, lat.c) == (0.0, 6.0, 4)  # plane x2, left wall, the pair
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS\n0.0 6.0"))  # old dumps: no flags
    assert (lat.left, lat.right) == (0.0, 6.0)
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS fs ff pp\n-1 7"))
    assert (lat.left, lat.right, lat.c) == (-1.0, 4.0, 4)  # shrink-wrapped right: tight
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS xy xz yz ff ff pp\n0 6 0"))
    assert (lat.left, lat.right) == (0.0, 6.0)  # triclinic without tilt
    lat = read_packing(_dump(tmp_path, None))
    assert (lat.left, lat.right, lat.c) == (0.0, 4.0, 5)  # no BOX BOUNDS: the tight box
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS ff ff pp\n0 6"), right="none")
    assert lat.right is None  # the caller's wall wins


@pytest.mark.parametrize("box, message", [
    ("ITEM: BOX BOUNDS pp ff pp\n0 4", r"line 5: the x boundary is periodic.*forceset --left"),
    ("ITEM: BOX BOUNDS xy xz yz ff ff pp\n0 4 0.5", r"tilted \(xy = 0.5\)"),
    ("ITEM: BOX BOUNDS qq ff pp\n0 4", r"line 5: x boundary flag 'qq'"),
    ("ITEM: BOX BOUNDS ff ff pp\n0 four", r"line 6, field 'xhi': 'four' is not a number"),
    ("ITEM: BOX BOUNDS ff ff pp\n0 4 1", r"line 6: 3 fields, the x bounds need 2"),
    ("ITEM: BOX BOUNDS ff ff pp\n0.5 4", r"disk 0 overlaps the left wall"),
])
def test_lammps_box_bounds_refused_naming_the_line(tmp_path, box, message):
    """A periodic or tilted x is not a wall (refused unless the caller gives the walls), a
    bad flag or bound names its line, a wall through a disk is an overlap."""
    with pytest.raises(Overlap if "overlaps" in message else InvalidFile, match=message):
        read_packing(_dump(tmp_path, box))


def test_lammps_periodic_x_with_the_callers_walls(tmp_path):
    lat = read_packing(_dump(tmp_path, "ITEM: BOX BOUNDS pp ff pp\n0 4"), left="none",
                       right="none")
    assert (lat.left, lat.right, lat.c) == (None, None, 3)


@pytest.mark.parametrize("text, message", [
    ("x,y\n1,1\n", r"line 1: the header must name the columns x, y, r \(missing r"),
    ("x,y,r\n1,1,1\n2,2\n", r"line 3: 2 fields, the header has 3"),
    ("x,y,r\n1,1,1\n3,1,-1\n", r"line 3, field 'r': must be > 0"),
    ("x,y,r\n1,nan,1\n", r"line 2, field 'y': 'nan' is not finite"),
    ("x,y,r,m\n1,1,1,zero\n", r"line 2, field 'm': 'zero' is not a number"),
    ("# box: left=0 top=3\nx,y,r\n", r"line 1: box comment field 'top'"),
    ("x,y,r,box_left\n1,1,1,0\n3,1,1,0.5\n",
     r"line 3, field 'box_left': '0.5', but the left wall is 0.0 above"),
    ("# box: left=0 right=4\nx,y,r,box_right\n1,1,1,5\n",
     r"line 3, field 'box_right': '5', but the right wall is 4.0 above"),
    ("x,y,r,box_right\n1,1,1,wall\n", r"line 2, field 'box_right': 'wall' is not a number"),
    ("x,y,r\n", r"no disks"),
    ("", r"no header line"),
])
def test_bad_csv_refused_by_line_and_field(tmp_path, text, message):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InvalidFile, match=message):
        read_disks(f)


def test_bad_npz_and_binary(tmp_path):
    f = tmp_path / "bad.npz"
    np.savez(f, x=np.ones(2), y=np.ones(2))
    with pytest.raises(InvalidFile, match="array 'r' missing"):
        read_disks(f)
    g = tmp_path / "b.csv"
    g.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(InvalidFile, match="not a packing file"):
        read_disks(g)
    with pytest.raises(FileNotFoundError):
        read_disks(tmp_path / "missing.csv")


def test_npz_errors_name_the_array_entry_and_a_run_is_named(tmp_path):
    """user25: an .npz with NaN said 'line 1' (an archive has no lines); a run file said
    "array 'x' missing" instead of naming what it is."""
    import numpy as np
    import pytest

    from rigidlcp import models
    from rigidlcp.lcp.errors import InvalidFile
    from rigidlcp.models.packing_io import read_packing
    from rigidlcp.models.runio import save_run

    f = tmp_path / "pn.npz"
    np.savez(f, x=[1.0, 3.0], y=[1.0, np.nan], r=[1.0, 1.0])
    with pytest.raises(InvalidFile, match=r"array 'y', entry 1: 'nan' is not finite"):
        read_packing(f)
    run = models.simulate(models.System(models.rectangular(2, 1)), seed=1)
    save_run(run, tmp_path / "run.npz")
    with pytest.raises(InvalidFile, match="is a run saved by `rigidlcp simulate`, not a packing"):
        read_packing(tmp_path / "run.npz")


def test_lammps_diameter_column_and_a_bad_atom_count(tmp_path):
    """LAMMPS's per-atom `diameter` (dump custom ... diameter) is read as 2 r; an atom count
    that is not a whole number was truncated, now refused naming its line."""
    f = tmp_path / "dump.atoms"
    f.write_text(LAMMPS.replace(" radius mass", " diameter mass")
                 .replace("1.0 1.0 0 1.0 2.0", "1.0 1.0 0 2.0 2.0")
                 .replace("3.0 1.0 0 1.0 2.0", "3.0 1.0 0 2.0 2.0"))
    d = read_disks(f)
    assert np.array_equal(d.r, [1.0, 1.0]) and read_packing(f).c == 5
    f.write_text(LAMMPS.replace("ITEM: NUMBER OF ATOMS\n2\n", "ITEM: NUMBER OF ATOMS\n2.5\n"))
    with pytest.raises(InvalidFile, match=r"line 4: the number of atoms must be an integer"):
        read_disks(f)
    f.write_text(LAMMPS.replace(" radius mass", " r mass"))
    with pytest.raises(InvalidFile, match=r"radius or diameter \(missing radius\)"):
        read_disks(f)


def test_lammps_trajectory_is_refused_naming_its_last_snapshot(tmp_path):
    """A dump of several snapshots was read silently as its first one (in a trajectory, the
    start, not the packing at rest); it is refused naming where the last one starts, and that
    snapshot alone, cut there, reads."""
    last = LAMMPS.replace("TIMESTEP\n0\n", "TIMESTEP\n500\n").replace("3.0 1.0", "3.5 1.0")
    f = tmp_path / "traj.dump"
    f.write_text(LAMMPS + last)
    first_lines = len(LAMMPS.splitlines())
    with pytest.raises(InvalidFile, match=r"holds 2 snapshots \(timesteps 0 to 500\), a "
                       r"packing is one: ") as exc:
        read_disks(f)  # the command that cuts the last one, to a new file beside it
    assert str(exc.value).endswith(f"tail -n +{first_lines + 1} {f} > "
                                   f"{tmp_path / 'traj_last.dump'}")
    cut = tmp_path / "last.dump"
    cut.write_text("\n".join(f.read_text().splitlines()[first_lines:]) + "\n")
    assert np.array_equal(read_disks(cut).x, [[1, 1], [3.5, 1]])
    f.write_text(LAMMPS + "\n\n")  # blank lines after the atoms: one snapshot
    assert np.array_equal(read_disks(f).x, [[1, 1], [3, 1]])


def test_lammps_more_atoms_than_announced_is_refused(tmp_path):
    f = tmp_path / "dump.atoms"
    f.write_text(LAMMPS + "3 1 5.0 1.0 0 1.0 2.0\n")
    with pytest.raises(InvalidFile, match=r"line 12: more lines than the 2 atoms announced"):
        read_disks(f)
