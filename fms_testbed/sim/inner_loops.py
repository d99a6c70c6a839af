"""Inner loops run inside JSBSim as a ``<system>``, by default every second frame (60 Hz).

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
between this system and :mod:`fms_testbed.sim.jsbsim_core`.
"""

from __future__ import annotations
from fms_testbed.core.atmosphere import isa

#: Properties written from Python (inputs of the system).
INPUT_PROPERTIES = (
    "fms/ap/master", "fms/ap/bank-trigger", "fms/ap/yaw-trigger", "fms/ap/ny-trigger",
    "fms/ap/bank-engage", "fms/ap/yaw-engage", "fms/ap/ny-engage", "fms/ap/nx-engage",
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
OUTPUT_PROPERTIES = ("fms/meas/nx", "fms/meas/ny", "fms/throttle-out")


def _fn(name: str, body: str, clip: tuple[str, str] | None = None,
        outputs: tuple[str, ...] = ()) -> str:
    """An ``fcs_function`` component, optionally clipped and written to output properties."""
    extra = f"<clipto><min>{clip[0]}</min><max>{clip[1]}</max></clipto>" if clip else ""
    extra += "".join(f"<output>{o}</output>" for o in outputs)
    return f'  <fcs_function name="{name}"><function>{body}</function>{extra}</fcs_function>\n'


def _p(prop: str) -> str:
    return f"<property>{prop}</property>"


def _master(target: str, active: str) -> str:
    """While ``fms/ap/master`` is 0 (e.g. during trim) pass the control through unchanged."""
    return f"<ifthen><gt>{_p('fms/ap/master')}<v>0.5</v></gt>{active}{_p(target)}</ifthen>"


def _pid(name: str, error: str, gain: str, trigger: str) -> str:
    return (f'  <pid name="{name}"><input>{error}</input>'
            f"<kp>fms/gain/{gain}-kp</kp><ki>fms/gain/{gain}-ki</ki><kd>0</kd>"
            f"<trigger>{trigger}</trigger></pid>\n")


def _sum(*terms: str) -> str:
    return f"<sum>{''.join(terms)}</sum>"


def _prod(*terms: str) -> str:
    return f"<product>{''.join(terms)}</product>"


def _diff(a: str, b: str) -> str:
    return f"<difference>{a}{b}</difference>"


#: JSBSim's sea-level standard pressure in its unit, psf (FGPiston's 101325 Pa)
P_SL_PSF = 2116.22


def mixture_channel(n_engines: int, rate: str = "") -> str:
    """A channel holding each piston engine's mixture at its sea-level full-rich richness.

    JSBSim's piston model (``FGPiston::doFuelFlow``) makes the equivalence ratio
    φ = 1.3 · m · p_SL / p_amb from the mixture lever m, so a lever left full rich (m = 1)
    floods the engine as the air thins: the c172p's O-320 makes ~10 hp at 2,800 m and
    stops above (measured: full throttle, 150 km/h TAS). A pilot leans with altitude; this
    channel does it the way an altitude-compensating carburettor would, m = min(1, p_amb / p_SL),
    which keeps φ = 1.3 (the sea-level full-rich value, where the model's power peaks within
    a few per cent) at every altitude.

    Parameters
    ----------
    n_engines : engines whose ``fcs/mixture-cmd-norm[i]`` the channel writes
    rate : the channel's ``execrate`` attribute text (as the other channels)
    """
    return (f'<channel name="fms-mixture"{rate}>\n'
            + _fn("fms/mixture-out",
                  f"<quotient>{_p('atmosphere/P-psf')}<v>{P_SL_PSF}</v></quotient>",
                  clip=("0", "1"),
                  outputs=tuple(f"fcs/mixture-cmd-norm[{i}]" for i in range(n_engines)))
            + "</channel>\n")


def system_xml(n_engines: int, elevator_rate_max_ps: float, dt_s: float,
               frames_per_update: int = 1, piston: bool = False) -> str:
    """Return the ``<system>`` element (XML text) for an aircraft with ``n_engines`` engines.

    16 components in all (each costs JSBSim time every frame). Integrator triggers of the bank,
    yaw and n_y loops are written from Python on (dis)engagement (0 integrate, -1 reset); the n_x
    trigger is computed here for anti-windup (+1 holds the integrator while the throttle sits at a
    limit in the direction the error pushes).

    Parameters
    ----------
    n_engines : number of engines; the throttle command goes to every ``fcs/throttle-cmd-norm[i]``
    elevator_rate_max_ps : elevator command rate limit, normalised units per second
    dt_s : frame time, s (documentation only; JSBSim supplies the frame time)
    frames_per_update : the loops run every this many frames (JSBSim channel ``execrate``;
        JSBSim integrates the PIDs and rate-limits the actuator with the channel's step
        ``frames_per_update * dt_s``). Python writes commands between frames; they are
        sampled at the next update.
    piston : the engines are JSBSim piston engines: add :func:`mixture_channel`
    """
    decl = "".join(f'  <property value="0">{p}</property>\n' for p in INPUT_PROPERTIES)
    rate = f' execrate="{int(frames_per_update)}"' if frames_per_update > 1 else ""
    meas = _measurement_channel(rate)
    lateral = _lateral_channel(rate)
    longitudinal = _longitudinal_channel(rate, n_engines, elevator_rate_max_ps)
    return (f'<system name="fms-inner-loops">\n<!-- generated by fms_testbed.sim.inner_loops; '
            f"frame {dt_s:.6f} s ({1.0 / dt_s:.0f} Hz), loops every {frames_per_update} frame(s) "
            f"({1.0 / (dt_s * frames_per_update):.0f} Hz) -->\n"
            f"{decl}{meas}{lateral}{longitudinal}"
            f"{mixture_channel(n_engines, rate) if piston else ''}</system>\n")


def _measurement_channel(rate: str) -> str:
    """Measured load factors (wind axes) and the q̄ schedule ratio."""
    P = _p
    alpha, w = P("aero/alpha-rad"), P("inertia/weight-lbs")
    fx, fz = P("forces/fbx-total-lbs"), P("forces/fbz-total-lbs")
    return (
        f'<channel name="fms-measurements"{rate}>\n'
        + _fn("fms/meas/nx", f"<quotient>{_sum(_prod(fx, f'<cos>{alpha}</cos>'), _prod(fz, f'<sin>{alpha}</sin>'))}{w}</quotient>")
        + _fn("fms/meas/ny", f"<quotient>{_diff(_prod(fx, f'<sin>{alpha}</sin>'), _prod(fz, f'<cos>{alpha}</cos>'))}{w}</quotient>")
        # gain schedule: surface loops scale with q̄_ref / q̄ about the design point
        + _fn("fms/sched/qbar-ratio",
              f"<quotient>{P('fms/sched/qbar-ref-psf')}<max>{P('aero/qbar-psf')}<v>1</v></max></quotient>",
              clip=("0.25", "4"))
        + "</channel>\n")


def _lateral_channel(rate: str) -> str:
    """Bank hold (aileron) and yaw coordination (rudder)."""
    P = _p
    qr = P("fms/sched/qbar-ratio")
    tan_phi = f"<tan>{P('attitude/phi-rad')}</tan>"
    return (
        f'<channel name="fms-lateral"{rate}>\n'
        + _fn("fms/bank-err-rad", _prod(qr, _diff(P("fms/cmd/bank-rad"), P("attitude/phi-rad"))))
        + _pid("fms/bank-pid", "fms/bank-err-rad", "bank", "fms/ap/bank-trigger")
        + _fn("fms/aileron-out", _master("fcs/aileron-cmd-norm", _sum(
              P("fms/trim/aileron"), _prod(P("fms/ap/bank-engage"), _diff(
                  P("fms/bank-pid"), _prod(qr, P("fms/gain/bank-kd"), P("velocities/p-rad_sec")))))),
              clip=("-1", "1"), outputs=("fcs/aileron-cmd-norm",))
        + _pid("fms/yaw-pid", "aero/beta-rad", "yaw", "fms/ap/yaw-trigger")
        # yaw-rate error: r minus the coordinated-turn rate g tanφ / V (fps units)
        + _fn("fms/rudder-out", _master("fcs/rudder-cmd-norm", _sum(
              P("fms/trim/rudder"), _prod(P("fms/ap/yaw-engage"), _diff(
                  _prod(P("fms/gain/yaw-kd"), _diff(
                      P("velocities/r-rad_sec"),
                      f"<quotient>{_prod('<v>32.174</v>', tan_phi)}"
                      f"<max>{P('velocities/vt-fps')}<v>50</v></max></quotient>")),
                  P("fms/yaw-pid"))))),
              clip=("-1", "1"), outputs=("fcs/rudder-cmd-norm",))
        + "</channel>\n")


def _longitudinal_channel(rate: str, n_engines: int, elevator_rate_max_ps: float) -> str:
    """Normal load factor (elevator, rate limited) and tangential load factor (throttle, with
    anti-windup)."""
    P = _p
    qr = P("fms/sched/qbar-ratio")
    thr_out = P("fms/throttle-out")
    return (
        f'<channel name="fms-longitudinal"{rate}>\n'
        + _fn("fms/ny-err", _prod(qr, _diff(P("fms/cmd/ny"), P("fms/meas/ny"))))
        + _pid("fms/ny-pid", "fms/ny-err", "ny", "fms/ap/ny-trigger")
        + _fn("fms/elevator-out", _master("fcs/elevator-cmd-norm", _sum(
              P("fms/trim/elevator"), _prod(P("fms/ap/ny-engage"), _diff(
                  _prod(qr, P("fms/gain/ny-kd"), P("velocities/q-rad_sec")),
                  _sum(P("fms/ny-pid"), _prod(qr, P("fms/gain/ny-kff"),
                                               _diff(P("fms/cmd/ny"), "<v>1</v>"))))))))
        + '  <actuator name="fms/elevator-act"><input>fms/elevator-out</input>'
          f"<rate_limit>{elevator_rate_max_ps:.6g}</rate_limit>"
          "<clipto><min>-1</min><max>1</max></clipto><output>fcs/elevator-cmd-norm</output></actuator>\n"
        + _fn("fms/nx-err", _diff(P("fms/cmd/nx"), P("fms/meas/nx")))
        # anti-windup on the previous frame's (clipped) throttle
        + _fn("fms/nx-trigger",
              f"<ifthen><lt>{P('fms/ap/nx-engage')}<v>0.5</v></lt><v>-1</v>"
              f"<ifthen><or><and><ge>{thr_out}<difference>{P('fms/limit/throttle-max')}<v>1e-6</v></difference></ge>"
              f"<gt>{P('fms/nx-err')}<v>0</v></gt></and>"
              f"<and><le>{thr_out}<sum>{P('fms/limit/throttle-min')}<v>1e-6</v></sum></le>"
              f"<lt>{P('fms/nx-err')}<v>0</v></lt></and></or><v>1</v><v>0</v></ifthen></ifthen>")
        + _pid("fms/nx-pid", "fms/nx-err", "nx", "fms/nx-trigger")
        + _fn("fms/throttle-out", _master(
              "fcs/throttle-cmd-norm[0]",
              f"<ifthen><gt>{P('fms/ap/nx-engage')}<v>0.5</v></gt>"
              + _sum(P("fms/trim/throttle"), P("fms/nx-pid"), _prod(P("fms/gain/nx-kff"), P("fms/cmd/nx")))
              + f"{P('fms/cmd/throttle')}</ifthen>"),
              clip=("fms/limit/throttle-min", "fms/limit/throttle-max"),
              outputs=tuple(f"fcs/throttle-cmd-norm[{i}]" for i in range(n_engines)))
        + "</channel>\n")


def gain_properties(cfg) -> dict[str, float]:
    """Map an :class:`~fms_testbed.config.aircraft.AircraftConfig`'s inner-loop tuning to ``fms/*``
    properties (gains, limits, and the schedule's reference dynamic pressure)."""
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
