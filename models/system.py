"""A system: a lattice, the three coefficients of friction, the disks' inertia and the driving.

Frame (docs/mechanics.md): the box's frame, x to the right, y up. The box moves relative to the
plane with velocity V(t) = V0 + gamma t, so in the box frame every disk feels gravity (0, -m g)
and the inertial force (-m gamma, 0); the walls are fixed and the plane moves with velocity
-V(t). Constant velocity is gamma = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .lattice import KINDS, PLANE, InvalidSystem, Lattice


def _float(name: str, value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InvalidSystem(f"{name} must be a number, got {value!r}") from None


def _nonneg(name: str, value) -> float:
    v = _float(name, value)
    if not np.isfinite(v) or v < 0:
        raise InvalidSystem(f"{name} must be a finite number >= 0, got {value!r}")
    return v


def _positive(name: str, value) -> float:
    v = _float(name, value)
    if not (np.isfinite(v) and v > 0):
        raise InvalidSystem(f"{name} must be a finite number > 0, got {value!r}")
    return v


def _finite(name: str, value) -> float:
    v = _float(name, value)
    if not np.isfinite(v):
        raise InvalidSystem(f"{name} must be finite, got {value!r}")
    return v


#: The default friction coefficients of every entry point (models.System, `rigidlcp simulate`,
#: `sweep`, `forces`): those of the paper's Figs. 7, 9 and 10. (`rigidlcp nullspace` alone uses
#: one coefficient everywhere, 0.3, so that the structures of Fig. 5 stay local.)
DEFAULT_MU = {"mu_pp": 0.1, "mu_plane": 0.2, "mu_wall": 0.0}


@dataclass(frozen=True, eq=False)
class System:
    """Lattice + friction (mu_pp particle-particle, mu_plane, mu_wall) + m, I, g + driving.

    gamma: constant acceleration of the box relative to the plane (either sign; 0 = constant
    velocity); V0: the relative velocity at t = 0. The friction coefficients default to
    DEFAULT_MU (the paper's Figs. 7, 9, 10).

    Per disk: `masses` and `inertias` (p,) are the lattice's when it carries them (a packing
    read from a file), else every disk has mass `mass` (default 1) and I_i = `inertia`, or by
    default m r_i^2 / 2 (uniform disks). `mass` and `inertia` then hold the means (scales).
    """

    lattice: Lattice
    mu_pp: float = DEFAULT_MU["mu_pp"]
    mu_plane: float = DEFAULT_MU["mu_plane"]
    mu_wall: float = DEFAULT_MU["mu_wall"]
    gamma: float = 0.0
    V0: float = 0.0
    mass: float | None = None
    inertia: float | None = None
    g: float = 1.0
    mu: np.ndarray = field(init=False, repr=False)
    masses: np.ndarray = field(init=False, repr=False)
    inertias: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.lattice, Lattice):
            got = type(self.lattice).__name__
            raise InvalidSystem(f"lattice must be a models.Lattice, got {got}")
        for name in ("mu_pp", "mu_plane", "mu_wall"):
            object.__setattr__(self, name, _nonneg(name, getattr(self, name)))
        object.__setattr__(self, "gamma", _finite("gamma", self.gamma))
        object.__setattr__(self, "V0", _finite("V0", self.V0))
        object.__setattr__(self, "g", _nonneg("g", self.g))
        self._set_inertia()
        coef = {"pp": self.mu_pp, "plane": self.mu_plane, "wall": self.mu_wall}
        mu = np.array([coef[k] for k in self.lattice.kind], dtype=float)
        mu.setflags(write=False)
        object.__setattr__(self, "mu", mu)

    def _set_inertia(self) -> None:
        """masses, inertias (p,) and their scales mass, inertia (class docstring)."""
        lat, p = self.lattice, self.lattice.p
        for name, given, own in (("mass", self.mass, lat.masses),
                                 ("inertia", self.inertia, lat.inertias)):
            if own is not None and given is not None:
                raise InvalidSystem(f"{name}: the packing gives every disk's {name}; "
                                    f"pass {name}=None")
        if lat.masses is not None:
            masses, mass = lat.masses, float(np.mean(lat.masses))
        else:
            mass = _positive("mass", 1.0 if self.mass is None else self.mass)
            masses = np.full(p, mass)
        if lat.inertias is not None:
            inertias, inertia = lat.inertias, float(np.mean(lat.inertias))
        elif self.inertia is not None:
            inertia = _positive("inertia", self.inertia)
            inertias = np.full(p, inertia)
        else:  # uniform disks, I_i = m_i r_i^2 / 2
            inertias = 0.5 * masses * lat.radii**2
            inertia = (0.5 * mass * lat.radius**2 if lat.regular and lat.masses is None
                       else float(np.mean(inertias)))
            inertia = _positive("inertia", inertia)
        for name, arr in (("masses", masses), ("inertias", inertias)):
            arr = np.array(arr, dtype=float)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "inertia", inertia)

    @property
    def uniform(self) -> bool:
        """Every disk has the same mass and moment of inertia (the paper's arrays)."""
        return bool(np.all(self.masses == self.masses[0]) and
                    np.all(self.inertias == self.inertias[0])) if self.p else True

    @property
    def p(self) -> int:
        return self.lattice.p

    @property
    def c(self) -> int:
        return self.lattice.c

    @property
    def total_mass(self) -> float:
        """m_g of Eq. (2.1): the sum of the disks' masses."""
        if self.lattice.masses is None:
            return self.mass * self.p
        return float(np.sum(self.masses))

    @property
    def plane_contacts(self) -> np.ndarray:
        return np.flatnonzero(self.lattice.j == PLANE)

    def describe(self) -> dict:
        """Parameters as a JSON-friendly dict (for run metadata)."""
        lat = self.lattice
        out = {
            "lattice": lat.name, "lx": lat.lx, "ly": lat.ly, "radius": lat.radius,
            "mu_pp": self.mu_pp, "mu_plane": self.mu_plane, "mu_wall": self.mu_wall,
            "gamma": self.gamma, "V0": self.V0, "mass": self.mass, "inertia": self.inertia,
            "g": self.g,
        }
        if not lat.regular:  # the geometry itself is saved by models.runio
            out.update(p=lat.p, c=lat.c, left=lat.left, right=lat.right, gap_tol=lat.gap_tol)
        return out


def make_system(lattice: str, lx: int, ly: int, **params) -> System:
    """System from a lattice name and size plus System's keyword parameters."""
    from .lattice import make_lattice

    radius = params.pop("radius", 1.0)
    return System(make_lattice(lattice, lx, ly, radius), **params)


__all__ = ["System", "make_system", "KINDS", "DEFAULT_MU"]
