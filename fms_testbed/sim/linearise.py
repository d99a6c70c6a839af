"""Linear models of the trimmed JSBSim aircraft at a design point (JSBSim's ``FGLinearization``).

At a trimmed state JSBSim's ``FGLinearization`` returns ``ẋ = A x + B u`` over its 12 states
(Vt, α, θ, q, β, φ, p, ψ, r, latitude, longitude, altitude; ft, rad, s) and 4 inputs (throttle,
aileron, elevator, rudder commands, normalised). While it runs the inner loops are switched off
(``fms/ap/master`` 0: the commands pass straight to the model) and the controls are held at trim.
The model is reduced to the states the laws see, in SI:

* longitudinal: states (V_mps, alpha_rad, theta_rad, q_rps, h_m) — the speed column of A by
  central differences on the nonlinear model (:func:`speed_column`) — plus a first-order engine lag
  ``ẋ_e = (δT - x_e) / τ_e`` (JSBSim's linearisation holds thrust at the throttle: the engine has
  no state there; τ_e is measured on the nonlinear model, :func:`engine_lag_s`); inputs
  (throttle, elevator); outputs V, α, θ, q, h, γ = θ - α and the two load factors the inner loops
  measure, linearised about level flight from the same rows::

      Δn_x = V̇ / g + γ,        Δn_y = (V0 / g) γ̇ = (V0 / g)(q - α̇)

* lateral: states (beta_rad, phi_rad, p_rps, r_rps, psi_rad); inputs (aileron, rudder).

A design point's mass is set through the fuel tanks (scaled together) and a CG shift through the
ballast point mass the sanitised model carries (:data:`BALLAST`); both are set before the trim.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control as ct
import jsbsim
import numpy as np

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import FT_M, G0_MPS2, LB_KG, SLUG_KG
from fms_testbed.sim.jsbsim_core import JSBSimAircraft, TrimResult

LON_STATES = ("V_mps", "alpha_rad", "theta_rad", "q_rps", "h_m")
"""Longitudinal airframe states (SI), before the engine-lag state ``thrust_norm``."""
LON_OUTPUTS = ("V", "alpha", "theta", "q", "h", "gamma", "nx", "ny")
"""Longitudinal outputs: m/s, rad, rad, rad/s, m, rad, g, g (deviations from trim)."""
LAT_STATES = ("beta_rad", "phi_rad", "p_rps", "r_rps", "psi_rad")
"""Lateral-directional states (SI)."""
_JSB_LON = ("Vt", "Alpha", "Theta", "Q", "Alt")
_JSB_LAT = ("Beta", "Phi", "P", "R", "Psi")
_SCALE = {"Vt": FT_M, "Alt": FT_M}
BALLAST = "fms-ballast"
"""Name of the zero-weight point mass the sanitised models carry for CG shifts."""


@dataclass(frozen=True, slots=True)
class DesignPoint:
    """Where the aircraft is linearised and the laws are tuned.

    Attributes
    ----------
    alt_m : altitude, m;  tas_mps : true airspeed, m/s
    mass_kg : gross mass, kg (None: the model's loaded mass)
    config : ``"clean"`` or ``"approach"`` (the aircraft file's landing flap, gear down)
    cg_shift_m : centre-of-gravity shift aft (+) or forward (-), m
    """

    alt_m: float
    tas_mps: float
    mass_kg: float | None = None
    config: str = "clean"
    cg_shift_m: float = 0.0

    def label(self) -> str:
        """Short text naming the point (alt m, TAS m/s, mass t, config)."""
        m = "" if self.mass_kg is None else f" {self.mass_kg / 1000:.1f} t"
        cg = f" cg{self.cg_shift_m:+.2f} m" if self.cg_shift_m else ""
        return f"{self.alt_m:.0f} m {self.tas_mps:.0f} m/s{m} {self.config}{cg}"


@dataclass(frozen=True)
class AirframeModel:
    """Linear airframe at a design point (python-control systems with named signals).

    Attributes
    ----------
    lon : longitudinal StateSpace, inputs (throttle, elevator), outputs :data:`LON_OUTPUTS`
    lat : lateral StateSpace, inputs (aileron, rudder), outputs (beta, phi, p, r, psi)
    trim : the trimmed condition;  point : the design point
    mass_kg : mass, kg;  qbar_pa : dynamic pressure, Pa;  engine_lag_s : τ_e, s
    """

    lon: ct.StateSpace
    lat: ct.StateSpace
    trim: TrimResult
    point: DesignPoint
    mass_kg: float
    qbar_pa: float
    engine_lag_s: float

    def __reduce__(self):
        """Pickle through plain arrays (python-control systems hold lambdas): process pools."""
        return (_rebuild_model, (_ss_parts(self.lon), _ss_parts(self.lat), self.trim, self.point,
                                 self.mass_kg, self.qbar_pa, self.engine_lag_s))


def _ss_parts(sys: ct.StateSpace) -> tuple:
    return (np.asarray(sys.A), np.asarray(sys.B), np.asarray(sys.C), np.asarray(sys.D),
            list(sys.input_labels), list(sys.output_labels), list(sys.state_labels), sys.name)


def _ss_from(parts: tuple) -> ct.StateSpace:
    A, B, C, D, ins, outs, states, name = parts
    return ct.ss(A, B, C, D, inputs=ins, outputs=outs, states=states, name=name)


def _rebuild_model(lon, lat, *rest) -> "AirframeModel":
    return AirframeModel(_ss_from(lon), _ss_from(lat), *rest)


def _tanks(fdm) -> list[float]:
    """Contents of every tank, lbs."""
    n = fdm.query_property_catalog("/contents-lbs").count("contents-lbs")
    return [fdm[f"propulsion/tank[{i}]/contents-lbs"] for i in range(n)]


def set_mass_and_cg(ac: JSBSimAircraft, mass_kg: float | None, cg_shift_m: float) -> float:
    """Set the gross mass and shift the CG before a trim: mass removed from the fuel (all tanks
    scaled by one factor; the CG moves with the fuel, as when it burns), mass added as ballast
    (:data:`BALLAST`); for a CG shift the ballast is at least 5 % of the weight (fuel reduced to
    keep the mass). A ballast is placed where the first moment puts the CG at ``x_cg0 + Δx``:
    ``x_b = ((x_cg0 + Δx)(W1 + w_b) - W1 x1) / w_b`` (W1, x1: weight and CG after the fuel).

    Parameters
    ----------
    ac : a freshly loaded aircraft;  mass_kg : target mass, kg (None: keep)
    cg_shift_m : CG shift, m, + aft

    Returns
    -------
    the CG shift obtained, m (JSBSim's ``inertia/cg-x-in`` after minus before)

    Raises
    ------
    UserError
        When the fuel cannot give the mass.
    """
    fdm = ac.fdm
    fdm.run_ic()
    w_lbs, cg0_in = fdm["inertia/weight-lbs"], fdm["inertia/cg-x-in"]
    target = w_lbs if mass_kg is None else mass_kg / LB_KG
    ballast = max(0.05 * target if cg_shift_m else 0.0, target - w_lbs)
    tanks = _tanks(fdm)
    fuel = sum(tanks)
    need = fuel + (target - w_lbs) - ballast
    if not 0.0 <= need <= fuel + 1e-6 or fuel <= 0:
        raise UserError(f"{ac.cfg.name}: mass {target * LB_KG:.0f} kg with a CG shift of "
                        f"{cg_shift_m:g} m is beyond what the fuel ({fuel * LB_KG:.0f} kg) allows")
    for i, c in enumerate(tanks):
        fdm[f"propulsion/tank[{i}]/contents-lbs"] = c * need / fuel
    if ballast:
        idx = _ballast_index(fdm)
        if idx is None:
            raise UserError(f"{ac.cfg.jsbsim_model}: the sanitised model has no ballast point mass")
        fdm.run_ic()
        w1, x1 = fdm["inertia/weight-lbs"], fdm["inertia/cg-x-in"]
        # (W1 x1 + w_b x_b) / (W1 + w_b) = x0 + Δx
        x_b = ((cg0_in + cg_shift_m / 0.0254) * (w1 + ballast) - w1 * x1) / ballast
        fdm[f"inertia/pointmass-weight-lbs[{idx}]"] = ballast
        fdm[f"inertia/pointmass-location-X-inches[{idx}]"] = x_b
        fdm[f"inertia/pointmass-location-Z-inches[{idx}]"] = fdm["inertia/cg-z-in"]
    fdm.run_ic()
    return (fdm["inertia/cg-x-in"] - cg0_in) * 0.0254


def _ballast_index(fdm) -> int | None:
    """Index of the :data:`BALLAST` point mass (the last point mass of a sanitised model)."""
    n = 0
    while fdm.get_property_manager().hasNode(f"inertia/pointmass-weight-lbs[{n}]"):
        n += 1
    return n - 1 if n else None


def trim_point(cfg: AircraftConfig, point: DesignPoint) -> tuple[JSBSimAircraft, TrimResult]:
    """A fresh aircraft at ``point``'s mass and CG, trimmed level at its altitude, TAS and
    configuration (approach: the file's landing flap, gear down).

    Parameters
    ----------
    cfg : aircraft;  point : design point (m, m/s, kg)

    Raises
    ------
    TrimError
        When JSBSim cannot trim there.
    """
    ac = JSBSimAircraft(cfg)
    flap, gear = 0.0, False
    if point.config == "approach":
        if cfg.approach is None:
            raise UserError(f"{cfg.name}: no approach block, no approach configuration to tune")
        flap = next(f.cmd_norm for f in cfg.approach.flaps if f.name == cfg.approach.landing_flap)
        gear = True
    elif point.config != "clean":
        raise UserError(f"design point config {point.config!r}: expected clean or approach")
    set_mass_and_cg(ac, point.mass_kg, point.cg_shift_m)
    tr = ac.trim(point.alt_m, point.tas_mps, heading_deg=90.0, lat_deg=45.0,
                 flap_cmd_norm=flap, gear_down=gear)
    return ac, tr


def engine_lag_s(ac: JSBSimAircraft, step: float = 0.05, duration_s: float = 4.0) -> float:
    """Equivalent first-order lag of the engines, s: 63 % rise of the total thrust after a
    ``step`` throttle step (normalised) from trim, other controls fixed (inner loops off).
    Leaves the aircraft off trim (call it after :func:`_linearisation`).

    Parameters
    ----------
    ac : trimmed aircraft;  step : throttle step;  duration_s : observation time, s
    """
    fdm = ac.fdm
    n_eng = ac.n_engines
    fdm["fms/ap/master"] = 0.0
    fdm.run()                          # the first frame after a trim settles N2 on the throttle
    thr0 = fdm["fcs/throttle-cmd-norm[0]"]
    props = [f"propulsion/engine[{i}]/thrust-lbs" for i in range(n_eng)]
    f0 = sum(fdm[p] for p in props)
    for i in range(n_eng):
        fdm[f"fcs/throttle-cmd-norm[{i}]"] = thr0 + step
    n = int(duration_s / ac.dt_s)
    f = np.empty(n)
    for k in range(n):
        fdm.run()
        f[k] = sum(fdm[p] for p in props)
    fdm["fms/ap/master"] = 1.0
    rise = (f - f0) / (f[-1] - f0)
    hit = np.flatnonzero(rise >= 1.0 - math.exp(-1.0))
    return float((hit[0] + 1) * ac.dt_s) if len(hit) else duration_s


def _linearisation(ac: JSBSimAircraft, trim: TrimResult) -> jsbsim.FGLinearization:
    """JSBSim's linearisation at the trimmed state, inner loops off, controls at trim; the
    integration is resumed at the aircraft's frame time afterwards."""
    fdm = ac.fdm
    master = fdm["fms/ap/master"]
    fdm["fms/ap/master"] = 0.0
    for i in range(ac.n_engines):
        fdm[f"fcs/throttle-cmd-norm[{i}]"] = trim.throttle
    fdm["fcs/elevator-cmd-norm"] = trim.elevator
    lin = jsbsim.FGLinearization(fdm)
    # FGLinearization leaves the integration suspended with a zero frame time
    if fdm.integration_suspended():
        fdm.resume_integration()
    fdm.set_dt(ac.dt_s)
    fdm["fms/ap/master"] = master
    return lin


def _reduce(lin, states, inputs) -> tuple[np.ndarray, np.ndarray]:
    """A, B restricted to ``states`` x ``inputs`` (JSBSim names), converted to SI."""
    xi = [lin.x_names.index(s) for s in states]
    ui = [lin.u_names.index(u) for u in inputs]
    A = np.asarray(lin.system_matrix)[np.ix_(xi, xi)]
    B = np.asarray(lin.input_matrix)[np.ix_(xi, ui)]
    s = np.array([_SCALE.get(n, 1.0) for n in states])
    return s[:, None] * A / s[None, :], s[:, None] * B


def speed_column(ac: JSBSimAircraft, dv_mps: float = 1.0) -> np.ndarray:
    """∂(V̇, α̇, θ̇, q̇, ḣ)/∂V by central differences on the nonlinear model, SI: the trimmed body
    velocity scaled by (V ± dV)/V at fixed α and θ, the derivatives from JSBSim's accelerations
    after ``run_ic`` (``V̇ = (u u̇ + w ẇ)/V``, ``α̇ = (u ẇ - w u̇)/(u² + w²)``); the state is put
    back at the trim afterwards. Replaces FGLinearization's speed column, whose ∂V̇/∂V is about
    twice the central difference (its phugoid damping 0.12 against 0.045 in JSBSim's free
    response, 737 at 3,000 m).

    Parameters
    ----------
    ac : trimmed aircraft, inner loops off;  dv_mps : speed step, m/s
    """
    fdm = ac.fdm
    u0, w0, th0 = fdm["velocities/u-fps"], fdm["velocities/w-fps"], fdm["attitude/theta-rad"]
    V0 = math.hypot(u0, w0)

    def derivs(dv: float) -> np.ndarray:
        k = (V0 + dv / FT_M) / V0
        fdm["ic/u-fps"], fdm["ic/w-fps"], fdm["ic/v-fps"] = u0 * k, w0 * k, 0.0
        fdm["ic/theta-rad"] = th0
        fdm.run_ic()
        u, w = fdm["velocities/u-fps"], fdm["velocities/w-fps"]
        ud, wd = fdm["accelerations/udot-ft_sec2"], fdm["accelerations/wdot-ft_sec2"]
        return np.array([(u * ud + w * wd) / math.hypot(u, w) * FT_M,
                         (u * wd - w * ud) / (u * u + w * w), 0.0,
                         fdm["accelerations/qdot-rad_sec2"], 0.0])

    col = (derivs(dv_mps) - derivs(-dv_mps)) / (2.0 * dv_mps)
    derivs(0.0)
    return col


def longitudinal_ss(A: np.ndarray, B: np.ndarray, V0_mps: float, tau_e_s: float
                    ) -> ct.StateSpace:
    """Longitudinal StateSpace with the engine lag and the load-factor outputs.

    Parameters
    ----------
    A, B : SI matrices over :data:`LON_STATES` and inputs (throttle, elevator)
    V0_mps : trim TAS, m/s;  tau_e_s : engine lag, s

    Returns
    -------
    StateSpace, states LON_STATES + thrust_norm, inputs (throttle, elevator), outputs
    :data:`LON_OUTPUTS`
    """
    n = A.shape[0]
    Ae = np.zeros((n + 1, n + 1))
    Ae[:n, :n] = A
    Ae[:n, n] = B[:, 0]                  # thrust acts through the lag state
    Ae[n, n] = -1.0 / tau_e_s
    Be = np.zeros((n + 1, 2))
    Be[n, 0] = 1.0 / tau_e_s
    Be[:n, 1] = B[:, 1]
    iV, ia, ith, iq, ih = range(5)
    C = np.zeros((8, n + 1))
    D = np.zeros((8, 2))
    for k, i in enumerate((iV, ia, ith, iq, ih)):
        C[k, i] = 1.0
    C[5, ith], C[5, ia] = 1.0, -1.0
    C[6] = Ae[iV] / G0_MPS2 + C[5]
    D[6] = Be[iV] / G0_MPS2
    C[7] = (V0_mps / G0_MPS2) * (np.eye(n + 1)[iq] - Ae[ia])
    D[7] = -(V0_mps / G0_MPS2) * Be[ia]
    return ct.ss(Ae, Be, C, D, states=list(LON_STATES) + ["thrust_norm"],
                 inputs=["throttle", "elevator"], outputs=list(LON_OUTPUTS), name="airframe_lon")


def linearise(cfg: AircraftConfig, point: DesignPoint, ac: JSBSimAircraft | None = None,
              trim: TrimResult | None = None) -> AirframeModel:
    """Trim ``cfg`` at ``point`` (unless ``ac``/``trim`` are given) and linearise it with
    JSBSim's ``FGLinearization``, the longitudinal speed column by central differences
    (:func:`speed_column`); see the module docstring.

    Parameters
    ----------
    cfg : aircraft;  point : design point
    ac, trim : an aircraft already trimmed at ``point`` and its trim (optional)
    """
    if ac is None or trim is None:
        ac, trim = trim_point(cfg, point)
    fdm = ac.fdm
    lin = _linearisation(ac, trim)
    A, B = _reduce(lin, _JSB_LON, ("ThtlCmd", "DeCmd"))
    fdm["fms/ap/master"] = 0.0
    A[:, 0] = speed_column(ac)
    fdm["fms/ap/master"] = 1.0
    V0 = trim.tas_mps
    qbar_pa = fdm["aero/qbar-psf"] * 47.88025898
    mass = fdm["inertia/mass-slugs"] * SLUG_KG
    tau_e = engine_lag_s(ac)
    lon = longitudinal_ss(A, B, V0, tau_e)
    Al, Bl = _reduce(lin, _JSB_LAT, ("DaCmd", "DrCmd"))
    lat = ct.ss(Al, Bl, np.eye(5), np.zeros((5, 2)), states=list(LAT_STATES),
                inputs=["aileron", "rudder"], outputs=["beta", "phi", "p", "r", "psi"],
                name="airframe_lat")
    return AirframeModel(lon, lat, trim, point, float(mass), float(qbar_pa), tau_e)


@dataclass(frozen=True, slots=True)
class Mode:
    """One oscillatory mode: natural frequency (rad/s), damping ratio, period (s)."""

    wn_rps: float
    zeta: float

    @property
    def period_s(self) -> float:
        """Damped period 2π / (ω_n sqrt(1 - ζ²)), s."""
        return 2 * math.pi / (self.wn_rps * math.sqrt(max(1e-12, 1 - self.zeta ** 2)))


def longitudinal_modes(model: AirframeModel) -> tuple[Mode, Mode]:
    """(short period, phugoid) of the bare airframe of ``model`` (:class:`AirframeModel`, without
    the engine lag state), from the eigenvalues of the longitudinal A: the faster and the slower
    complex pair."""
    A = np.asarray(model.lon.A)[:5, :5]
    ev = [e for e in np.linalg.eigvals(A) if e.imag > 1e-6]
    if len(ev) < 2:
        raise UserError(f"{model.point.label()}: the longitudinal model has "
                        f"{len(ev)} oscillatory modes, expected short period and phugoid")
    ev.sort(key=abs)
    ph, sp = ev[0], ev[-1]
    return (Mode(abs(sp), -sp.real / abs(sp)), Mode(abs(ph), -ph.real / abs(ph)))
