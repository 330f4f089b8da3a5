"""Metriplex: flexible multibody dynamics with dissipation, integrated with Energy-Entropy-Momentum
(EEM) schemes, midpoint, trapezoidal and SUNDIALS IDA.

    import metriplex
    r = metriplex.run("scenes/two_thermo_springs.xml", integrator="eem", dt=0.2, t_end=20)
    r.history["energy"], r.summary["max_relative_energy_drift"]

See docs/library.md.
"""
from dataclasses import dataclass


@dataclass
class Result:
    """One run: history maps every history.csv column to a numpy array (one entry per step);
    summary is summary.json as a dict (steps, newton_iterations, wall_seconds,
    max_relative_energy_drift, status, ...); bodies and joints map each rigid body and each
    revolute or prismatic joint to a dict of numpy arrays named as in bodies.csv and joints.csv;
    budget (run with budget=True) maps each scene element to its columns of budget.csv."""

    history: dict
    summary: dict
    bodies: dict
    joints: dict
    budget: dict

    @property
    def ok(self):
        """Whether the run reached t_end (summary["status"] == "ok")."""
        return self.summary["status"] == "ok"


from ._metriplex import InputError, Scene, run  # noqa: E402  (run builds Result)

__all__ = ["InputError", "Result", "Scene", "run"]
