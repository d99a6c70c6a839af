"""Inner loops run inside JSBSim as a ``<system>`` at the full frame rate (120 Hz).

Four loops, each with proportional and integral action and an engage flag:

* bank hold: aileron from bank error with roll-rate damping,
  ``δa = δa_trim + kp e_φ + ki ∫e_φ - kd p``
* yaw coordination: rudder from sideslip with yaw-rate damping,
  ``δr = δr_trim - (kp β + ki ∫β) + kd (r - g tanφ / V)`` (positive rudder yaws nose left)
* normal load factor: elevator from the n_y error with pitch-rate damping,
  ``δe = δe_trim - (kp e_ny + ki ∫e_ny + kff (n_y,cmd - 1)) + kd q``, rate limited
* tangential load factor: throttle from the n_x error,
  ``δT = δT_trim + kff n_x,cmd + kp e_nx + ki ∫e_nx``, clipped to [idle, max], integrator held while clipped.

Measured load factors behave like an accelerometer along the wind axes (coupled-law note):
``n_x = (F_x cos α + F_z sin α) / W``, ``n_y = (F_x sin α - F_z cos α) / W`` from JSBSim's total
body forces (gravity excluded).

Gain schedule: the surface loops' errors and damping terms are multiplied by
``q̄_ref / q̄`` (clipped to [0.25, 4]), the reference being the aircraft's design point (``default_condition``), where the gains
in its file were tuned.

Gains and commands are properties under ``fms/`` that Python writes; the XML never holds numbers
from the aircraft file, so tuning stays in ``aircraft/*.yaml``. The property names are the contract
between this system and :mod:`fms_testbed.jsbsim_core`.
"""

from __future__ import annotations

import math

#: Properties written from Python (inputs of the system).
INPUT_PROPERTIES = (
    "fms/ap/master", "fms/ap/bank-engage", "fms/ap/yaw-engage", "fms/ap/ny-engage", "fms/ap/nx-engage",
    "fms/cmd/bank-rad", "fms/cmd/ny", "fms/cmd/nx", "fms/cmd/throttle",
    "fms/trim/elevator", "fms/trim/aileron", "fms/trim/rudder", "fms/trim/throttle",
    "fms/gain/bank-kp", "fms/gain/bank-ki", "fms/gain/bank-kd",
    "fms/gain/yaw-kp", "fms/gain/yaw-ki", "fms/gain/yaw-kd",
    "fms/gain/ny-kp", "fms/gain/ny-ki", "fms/gain/ny-kd",
    "fms/gain/ny-kff", "fms/gain/nx-kp", "fms/gain/nx-ki", "fms/gain/nx-kff",
    "fms/limit/throttle-min", "fms/limit/throttle-max",
    "fms/sched/qbar-ref-psf",
)

#: Properties the system computes and Python reads.
OUTPUT_PROPERTIES = ("fms/meas/nx", "fms/meas/ny", "fms/throttle-sat", "fms/throttle-out")


def _fn(name: str, body: str) -> str:
    return f'  <fcs_function name="{name}"><function>{body}</function></fcs_function>\n'


def _p(prop: str) -> str:
    return f"<property>{prop}</property>"


def _master(target: str, active: str) -> str:
    """While ``fms/ap/master`` is 0 (e.g. during trim) pass the control through unchanged."""
    return f"<ifthen><gt>{_p('fms/ap/master')}<v>0.5</v></gt>{active}{_p(target)}</ifthen>"


def _pid(name: str, error: str, gain: str, trigger: str) -> str:
    return (f'  <pid name="{name}"><input>{error}</input>'
            f"<kp>fms/gain/{gain}-kp</kp><ki>fms/gain/{gain}-ki</ki><kd>0</kd>"
            f"<trigger>{trigger}</trigger></pid>\n")


def system_xml(n_engines: int, elevator_rate_max_ps: float, dt_s: float) -> str:
    """Return the ``<system>`` element (XML text) for an aircraft with ``n_engines`` engines.

    Parameters
    ----------
    n_engines : number of engines; the throttle command goes to every ``fcs/throttle-cmd-norm[i]``
    elevator_rate_max_ps : elevator command rate limit, normalised units per second
    dt_s : frame time, s (documentation only; JSBSim supplies the frame time)
    """
    decl = "".join(f'  <property value="0">{p}</property>\n' for p in INPUT_PROPERTIES)
    alpha = "aero/alpha-rad"
    w = "inertia/weight-lbs"
    meas = (
        '<channel name="fms-measurements">\n'
        + _fn("fms/meas/nx",
              f"<quotient><sum><product>{_p('forces/fbx-total-lbs')}<cos>{_p(alpha)}</cos></product>"
              f"<product>{_p('forces/fbz-total-lbs')}<sin>{_p(alpha)}</sin></product></sum>"
              f"{_p(w)}</quotient>")
        + _fn("fms/meas/ny",
              f"<quotient><difference><product>{_p('forces/fbx-total-lbs')}<sin>{_p(alpha)}</sin>"
              f"</product><product>{_p('forces/fbz-total-lbs')}<cos>{_p(alpha)}</cos></product>"
              f"</difference>{_p(w)}</quotient>")
        # gain schedule: surface loops scale with 1/qbar relative to the design point (the aircraft's default condition)
        + _fn("fms/sched/qbar-ratio",
              f"<max><v>0.25</v><min><v>4</v><quotient>{_p('fms/sched/qbar-ref-psf')}"
              f"<max>{_p('aero/qbar-psf')}<v>1</v></max></quotient></min></max>")
        + "</channel>\n")

    def reset_trigger(loop: str) -> str:
        # JSBSim pid trigger: 0 integrates, > 0 holds, < 0 resets the integrator.
        return _fn(f"fms/{loop}-trigger", f"<difference>{_p(f'fms/ap/{loop}-engage')}<v>1</v></difference>")

    lateral = (
        '<channel name="fms-lateral">\n'
        + reset_trigger("bank")
        + _fn("fms/bank-err-rad", f"<product>{_p('fms/sched/qbar-ratio')}<difference>{_p('fms/cmd/bank-rad')}"
              f"{_p('attitude/phi-rad')}</difference></product>")
        + _pid("fms/bank-pid", "fms/bank-err-rad", "bank", "fms/bank-trigger")
        + _fn("fms/aileron-out", _master("fcs/aileron-cmd-norm",
              f"<sum>{_p('fms/trim/aileron')}<product>{_p('fms/ap/bank-engage')}<difference>"
              f"{_p('fms/bank-pid')}<product>{_p('fms/sched/qbar-ratio')}{_p('fms/gain/bank-kd')}"
              f"{_p('velocities/p-rad_sec')}</product>"
              "</difference></product></sum>"))
        + '  <pure_gain name="fms/aileron-clip"><input>fms/aileron-out</input><gain>1</gain>'
          '<clipto><min>-1</min><max>1</max></clipto><output>fcs/aileron-cmd-norm</output></pure_gain>\n'
        + reset_trigger("yaw")
        + _fn("fms/yaw-rate-err-rps",
              f"<difference>{_p('velocities/r-rad_sec')}<quotient><product><v>32.174</v>"
              f"<tan>{_p('attitude/phi-rad')}</tan></product><max>{_p('velocities/vt-fps')}<v>50</v></max>"
              "</quotient></difference>")
        + _pid("fms/yaw-pid", "aero/beta-rad", "yaw", "fms/yaw-trigger")
        + _fn("fms/rudder-out", _master("fcs/rudder-cmd-norm",
              f"<sum>{_p('fms/trim/rudder')}<product>{_p('fms/ap/yaw-engage')}<difference>"
              f"<product>{_p('fms/gain/yaw-kd')}{_p('fms/yaw-rate-err-rps')}</product>{_p('fms/yaw-pid')}"
              "</difference></product></sum>"))
        + '  <pure_gain name="fms/rudder-clip"><input>fms/rudder-out</input><gain>1</gain>'
          '<clipto><min>-1</min><max>1</max></clipto><output>fcs/rudder-cmd-norm</output></pure_gain>\n'
        + "</channel>\n")

    longitudinal = (
        '<channel name="fms-longitudinal">\n'
        + reset_trigger("ny")
        + _fn("fms/ny-err", f"<product>{_p('fms/sched/qbar-ratio')}<difference>{_p('fms/cmd/ny')}"
              f"{_p('fms/meas/ny')}</difference></product>")
        + _pid("fms/ny-pid", "fms/ny-err", "ny", "fms/ny-trigger")
        + _fn("fms/elevator-out", _master("fcs/elevator-cmd-norm",
              f"<sum>{_p('fms/trim/elevator')}<product>{_p('fms/ap/ny-engage')}<difference>"
              f"<product>{_p('fms/sched/qbar-ratio')}{_p('fms/gain/ny-kd')}{_p('velocities/q-rad_sec')}"
              f"</product>{_p('fms/ny-pid')}"
              f"<product>{_p('fms/sched/qbar-ratio')}{_p('fms/gain/ny-kff')}<difference>{_p('fms/cmd/ny')}<v>1</v></difference>"
              "</product>"
              "</difference></product></sum>"))
        + '  <actuator name="fms/elevator-act"><input>fms/elevator-out</input>'
          f"<rate_limit>{elevator_rate_max_ps:.6g}</rate_limit>"
          '<clipto><min>-1</min><max>1</max></clipto><output>fcs/elevator-cmd-norm</output></actuator>\n'
        # Throttle: anti-windup trigger = -1 (reset) when disengaged, +1 (hold) when the previous
        # frame's unclipped command sat beyond a limit in the direction the error pushes.
        + _fn("fms/nx-err", f"<difference>{_p('fms/cmd/nx')}{_p('fms/meas/nx')}</difference>")
        + _fn("fms/nx-trigger",
              f"<ifthen><lt>{_p('fms/ap/nx-engage')}<v>0.5</v></lt><v>-1</v>"
              f"<ifthen><gt><product>{_p('fms/throttle-sat')}{_p('fms/nx-err')}</product><v>0</v></gt>"
              "<v>1</v><v>0</v></ifthen></ifthen>")
        + _pid("fms/nx-pid", "fms/nx-err", "nx", "fms/nx-trigger")
        + _fn("fms/throttle-raw", _master(
              "fcs/throttle-cmd-norm[0]",
              f"<ifthen><gt>{_p('fms/ap/nx-engage')}<v>0.5</v></gt>"
              f"<sum>{_p('fms/trim/throttle')}{_p('fms/nx-pid')}<product>{_p('fms/gain/nx-kff')}"
              f"{_p('fms/cmd/nx')}</product></sum>{_p('fms/cmd/throttle')}</ifthen>"))
        + _fn("fms/throttle-sat",
              f"<ifthen><ge>{_p('fms/throttle-raw')}{_p('fms/limit/throttle-max')}</ge><v>1</v>"
              f"<ifthen><le>{_p('fms/throttle-raw')}{_p('fms/limit/throttle-min')}</le><v>-1</v><v>0</v>"
              "</ifthen></ifthen>")
        + _fn("fms/throttle-out",
              f"<max><min>{_p('fms/throttle-raw')}{_p('fms/limit/throttle-max')}</min>"
              f"{_p('fms/limit/throttle-min')}</max>")
        + "".join(
            f'  <pure_gain name="fms/throttle-eng{i}"><input>fms/throttle-out</input><gain>1</gain>'
            f"<output>fcs/throttle-cmd-norm[{i}]</output></pure_gain>\n" for i in range(n_engines))
        + "</channel>\n")
    return (f'<system name="fms-inner-loops">\n<!-- generated by fms_testbed.inner_loops; '
            f"frame {dt_s:.6f} s ({1.0 / dt_s:.0f} Hz) -->\n{decl}{meas}{lateral}{longitudinal}</system>\n")


def gain_properties(cfg) -> dict[str, float]:
    """Map an :class:`~fms_testbed.aircraft.AircraftConfig`'s inner-loop tuning to ``fms/*``
    properties (gains, limits, and the schedule's reference dynamic pressure)."""
    from .atmosphere import isa

    gains = cfg.inner_loops
    _, _, rho = isa(cfg.default_condition.alt_m)
    qbar_pa = 0.5 * float(rho) * cfg.default_condition.tas_mps ** 2
    return {
        "fms/sched/qbar-ref-psf": qbar_pa / 47.88025898,
        "fms/gain/bank-kp": gains.bank.kp, "fms/gain/bank-ki": gains.bank.ki,
        "fms/gain/bank-kd": gains.bank.kd,
        "fms/gain/yaw-kp": gains.yaw.kp, "fms/gain/yaw-ki": gains.yaw.ki,
        "fms/gain/yaw-kd": gains.yaw.kd,
        "fms/gain/ny-kp": gains.ny.kp, "fms/gain/ny-ki": gains.ny.ki, "fms/gain/ny-kd": gains.ny.kd,
        "fms/gain/nx-kp": gains.nx.kp, "fms/gain/nx-ki": gains.nx.ki,
        "fms/gain/nx-kff": gains.nx.kff, "fms/gain/ny-kff": gains.ny.kff,
        "fms/limit/throttle-min": gains.throttle_min, "fms/limit/throttle-max": gains.throttle_max,
    }


def coordinated_turn_rate_rps(bank_rad: float, tas_mps: float, g_mps2: float = 9.80665) -> float:
    """Yaw rate of a coordinated level turn, rad/s: r = g tan(φ) / V."""
    return g_mps2 * math.tan(bank_rad) / max(tas_mps, 1.0)
