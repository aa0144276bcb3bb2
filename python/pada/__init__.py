"""pada for Python: how long a robot's gearboxes will last under the actions
a learner takes, and PADA to make them last.

- :class:`Fatigue` — the fatigue counter of the seed paper (Eqs. 3–7,
  Table I): backlash re-engagements, damage J and predicted MTBF per gearbox,
  exactly as ``pada mtbf`` computes them.
- :mod:`pada.wrappers` — Gymnasium wrappers: ``MtbfWrapper`` (the predicted
  MTBF in ``info``), ``PadaWrapper`` (Eq. 9, optionally driven by the wear
  governor with ``mtbf_budget=``) and ``LowPassWrapper`` (Eq. 8).
- :mod:`pada.envs` — pada's simulated robots as Gymnasium environments:
  ``pada/Pendulum-v0``, ``pada/PhysicalPendulum-v0``, ``pada/Leo-v0``,
  ``LeoVector(n)``, and ``pada/Robot-v0`` (a robot of your own, from its
  ``robot.toml`` and URDF).
- :func:`read_telemetry` — a recorded telemetry stream as numpy arrays.
"""

import numpy as _np

from . import _pada
from ._pada import PAPER_WINDOW_STEPS, RX28_TORQUE_PER_VOLT, WearGovernor

__all__ = [
    "Fatigue",
    "WearGovernor",
    "read_telemetry",
    "RX28_TORQUE_PER_VOLT",
    "PAPER_WINDOW_STEPS",
    "wrappers",
    "envs",
]


class Fatigue(_pada.Fatigue):
    """The fatigue counter of every gearbox of a robot (Eqs. 3–7, Table I).

    ``Fatigue(joints, rate_hz, *, torque_per_volt=None, window=1200, gearbox=None)``

    - ``joints``: gearboxes counted (1–64); ``rate_hz``: control steps per
      second (0 < rate_hz <= 1e6).
    - ``torque_per_volt``: when given, the values added are voltages and the
      gear torque is ``torque_per_volt * U`` (the paper's linear law, Section
      IV; ``pada.RX28_TORQUE_PER_VOLT`` for LEO's RX-28 servos).
    - ``window``: the paper's MTBF is over the first ``window`` steps (1200).
    - ``gearbox``: each gearbox's last gear (Eqs. 3–7). ``None`` is Table I
      (the RX-28's); a name of pada's table (``"RX-28"``, ``"MX-28"``,
      ``"XM430-W350"``, ``"XL430-W250"``, ``"XL330-M288"``), a TOML file's
      path, or a dict of the Table I fields (``theta_bl_rad``,
      ``k_nm_per_rad``, ``d``, ``sigma_f_mpa``, ``b_mm``, ``m_n_mm``,
      ``d_w_mm``, ``y_fa``, ``y_sa``, ``y_epsilon``, ``y_beta``, ``teeth``)
      applies to every gearbox; a list gives one per gearbox. Every gearbox
      but the RX-28's is an estimate (``gearbox_estimate``; see
      docs/reference/servos.md), and so is its MTBF.

    ``add(torques)`` counts one step (one value per gearbox, a number for
    one gearbox); ``add_many(array)`` a whole ``(steps, joints)`` array.
    Each sign change of a gearbox's torque through the backlash is a
    re-engagement (Eq. 3) whose impact torque T_e,max, stress σ_max and
    σ_ar give the cycles to failure N_f and the damage 1/N_f (Eqs. 4–7);
    the predicted MTBF is the elapsed time over the damage J.

    ``report()`` returns a dict with the per-gearbox lists
    ``reengagements``, ``damage``, ``mtbf_s`` and their ``window_*``
    counterparts, and ``robot_mtbf_s`` / ``robot_window_mtbf_s`` (the
    weakest gearbox), as ``pada mtbf`` reports them, and ``gearbox`` /
    ``gearbox_estimate`` (each gearbox's name and whether it is an estimate). Torques are counted in
    float32, as ``pada mtbf`` reads its log, so the figures are bit for bit
    ``pada mtbf``'s on the same torques. NaN or a wrong shape raises
    ``ValueError`` and counts nothing.
    """

    def add_many(self, torques):
        """Counts every row of ``torques``, a ``(steps, joints)`` array (or
        ``(steps,)`` for one gearbox), in order. Raises ``ValueError`` on a
        wrong shape or a non-finite value (naming its row and column) and
        then counts nothing."""
        a = _np.asarray(torques)
        if a.dtype == object or not (
            _np.issubdtype(a.dtype, _np.floating) or _np.issubdtype(a.dtype, _np.integer)
        ):
            raise ValueError(f"torques: valid is a numeric array, got dtype {a.dtype}")
        n = self.joints_count
        if a.ndim == 1 and n == 1:
            a = a.reshape(-1, 1)
        if a.ndim != 2 or a.shape[1] != n:
            raise ValueError(
                f"torques has shape {a.shape}: valid is (steps, {n}), one column per gearbox"
                + (" or (steps,)" if n == 1 else "")
            )
        a = _np.ascontiguousarray(a, dtype=_np.float64)
        self._add_f64_bytes(a.tobytes(), a.shape[0])


from .telemetry import read_telemetry  # noqa: E402
from . import wrappers  # noqa: E402
from . import envs  # noqa: E402  (registers the environments)
