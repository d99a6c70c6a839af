"""The INS/GNSS filter on recorded data: a strapdown mechanisation of the file's IMU increments
(:func:`~fms_testbed.sensors.imu.kinematics.forward_step`, the flight's) under the flight's
filter (:class:`~.ins_filter.InsGnssFilter`, its F and Q from the compensated measured f̄, ω̄
of each step, the GNSS measurement plug-ins, feedback into the mechanisation and the sensor
compensation). No truth is needed; with one, :func:`error_table` and :func:`error_stats` judge
the solution. File formats: :mod:`.replay_io`.

Steps: the increments are mechanised in navigation steps of ``nav_dt_s`` (a step also ends at
the first IMU sample at or after a GNSS fix's time of validity t_g); the filter predicts over
the step, then each fix due is used against the INS at the step's end t_k, its position moved
along the INS velocity by (t_k - t_g) (first order; t_k - t_g is below one IMU interval).
Heights are above the WGS-84 ellipsoid throughout.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numba import njit

from fms_testbed.core.earth import ellipsoidal_height_m, radii_m
from fms_testbed.core.state import NavSolution
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.navigation.ins_filter import FilterTuning, InsGnssFilter, _w_eb
from fms_testbed.navigation.inertial.strapdown import correct_row
from fms_testbed.sensors.gnss import GnssFix, GnssSpec
from fms_testbed.sensors.imu.kinematics import euler_to_quat, forward_step, new_row, quat_to_euler
from fms_testbed.sensors.sins.presets import ImuModel

OUT_COLS = ("t_s", "nav_lat_deg", "nav_lon_deg", "nav_alt_m", "nav_vn_mps", "nav_ve_mps",
            "nav_vd_mps", "nav_roll_deg", "nav_pitch_deg", "nav_heading_deg")
SIGMA_COLS = ("nav_north_sigma_m", "nav_east_sigma_m", "nav_alt_sigma_m", "nav_vn_sigma_mps",
              "nav_ve_sigma_mps", "nav_vd_sigma_mps", "nav_roll_sigma_deg", "nav_pitch_sigma_deg",
              "nav_heading_sigma_deg")
BIAS_COLS = ("bias_accel_x_ug", "bias_accel_y_ug", "bias_accel_z_ug", "bias_gyro_x_dph",
             "bias_gyro_y_dph", "bias_gyro_z_dph")
_NO_LEVER = np.zeros(3)


@njit(cache=True)
def mechanise_span(row, inc, t, k0, k1, comp):
    """Mechanise increments k0..k1-1 (``inc`` (n-1, 6): Δθ rad, Δv m/s, increment k over
    (t[k], t[k+1]]) on ``row`` (in place) after the compensation ``comp`` (6,: b̂_a m/s², b̂_g
    rad/s); returns (ΣΔv_c, ΣΔθ_c) (6,) and the last compensated rate Δθ_c/Δt (3,)."""
    s = np.zeros(6)
    w = np.zeros(3)
    for k in range(k0, k1):
        dt = t[k + 1] - t[k]
        cth = (inc[k, 0] - comp[3] * dt, inc[k, 1] - comp[4] * dt, inc[k, 2] - comp[5] * dt)
        cv = (inc[k, 3] - comp[0] * dt, inc[k, 4] - comp[1] * dt, inc[k, 5] - comp[2] * dt)
        forward_step(row, cth, cv, dt)
        for c in range(3):
            s[c] += cv[c]
            s[3 + c] += cth[c]
            w[c] = cth[c] / dt
    return s, w


def row_solution(row: np.ndarray, t_s: float) -> NavSolution:
    """The INS output of a mechanisation row (lat/lon rad, ellipsoidal height m, V ENU m/s,
    Euler rad) at ``t_s`` (s).

    Parameters
    ----------
    row : a :mod:`~fms_testbed.sensors.imu.kinematics` state row;  t_s : its time, s
    """
    roll, pitch, hdg = quat_to_euler((row[6], row[7], row[8], row[9]))
    return NavSolution(t_s, row[0], row[1], row[2], np.array([row[4], row[3], -row[5]]),
                       roll, pitch, hdg, {})


def euler_sigma_rad(P_att: np.ndarray, pitch_rad: float, heading_rad: float) -> np.ndarray:
    """1σ (3,) of roll, pitch, heading (rad) from the covariance of ε (E, N, U) rad², by the
    Jacobian of paper eq. 6.10.

    Parameters
    ----------
    P_att : (3, 3) covariance of ε;  pitch_rad, heading_rad : the attitude, rad
    """
    sp, cp = math.sin(heading_rad), math.cos(heading_rad)
    ct, tt = math.cos(pitch_rad), math.tan(pitch_rad)
    J = np.array([[-sp / ct, -cp / ct, 0.0], [-cp, sp, 0.0], [-tt * sp, -tt * cp, 1.0]])
    return np.sqrt(np.maximum(np.diag(J @ P_att @ J.T), 0.0))


def initial_row(init: dict) -> np.ndarray:
    """The mechanisation row of an init record (:mod:`.replay_io`: degrees, m, NED m/s).

    Parameters
    ----------
    init : the init mapping
    """
    q = euler_to_quat(math.radians(init["roll_deg"]), math.radians(init["pitch_deg"]),
                      math.radians(init["heading_deg"]))
    return new_row(math.radians(init["lat_deg"]), math.radians(init["lon_deg"]),
                   float(init["alt_m"]), np.array([init["vn_mps"], init["ve_mps"],
                                                   init["vd_mps"]], float), np.array(q))


def initial_covariance(flt: InsGnssFilter, sol: NavSolution, init: dict) -> None:
    """Set the filter's P0: the stationary-alignment map when ``init['alignment_s']`` is given
    (:meth:`~.ins_filter.InsGnssFilter.initialise`), else the sensor and GNSS blocks of that
    map with the navigation block diag(σ_p², σ_v², σ_level², σ_level², σ_heading²) of
    ``init['sigma']`` and no cross-covariance with the sensor states.

    Parameters
    ----------
    flt : the filter;  sol : the INS output at the start;  init : the init mapping
    """
    flt.initialise(sol, init.get("alignment_s"))
    if init.get("alignment_s"):
        return
    s = init["sigma"]
    lv, hd = math.radians(s["level_deg"]), math.radians(s["heading_deg"])
    flt.P[:9, :] = 0.0
    flt.P[:, :9] = 0.0
    flt.P[np.arange(9), np.arange(9)] = np.array(
        [s["pos_m"]] * 3 + [s["vel_mps"]] * 3 + [lv, lv, hd]) ** 2


def _fix(g: np.ndarray, sol: NavSolution, t_k: float, spec: GnssSpec) -> GnssFix:
    """A :class:`GnssFix` from a GNSS row (:func:`~.replay_io.read_gnss`) moved from its time of
    validity to ``t_k`` along the INS velocity of ``sol``; σ from the row or ``spec``."""
    dt = t_k - g[0]
    lat, lon, h = math.radians(g[1]), math.radians(g[2]), g[3]
    rm, rn = radii_m(lat)
    v = np.asarray(sol.v_enu_mps, float)
    lat += v[1] * dt / (rm + h)
    lon += v[0] * dt / ((rn + h) * math.cos(lat))
    w = spec.white_sigma
    ph = w[0] if math.isnan(g[7]) else g[7]
    pu = w[2] if math.isnan(g[8]) else g[8]
    vh = w[3] if math.isnan(g[9]) else g[9]
    vu = w[5] if math.isnan(g[10]) else g[10]
    v_enu = np.array([g[5], g[4], -g[6]])
    z = np.zeros(3)
    return GnssFix(t_k, t_k, lat, lon, h + v[2] * dt, v_enu, z, z, np.zeros(6),
                   np.array([ph, ph, pu]), np.array([vh, vh, vu]))


class Replay:
    """The flight's filter on recorded IMU increments and GNSS fixes (module docstring).

    Parameters
    ----------
    imu : the IMU's declared model (the filter's);  gnss : the receiver's declared model
    init : the init mapping (:func:`~.replay_io.read_init`)
    nav_dt_s : navigation step, s;  tuning : the filter's settings
    """

    def __init__(self, imu: ImuModel, gnss: GnssSpec, init: dict, nav_dt_s: float = 0.1,
                 tuning: FilterTuning = FilterTuning()):
        self.filter = InsGnssFilter(imu, gnss, None, tuning)
        self.gnss, self.init, self.nav_dt_s = gnss, init, float(nav_dt_s)
        self.row = initial_row(init)
        self.comp = np.zeros(6)
        self.counts = {"gnss_pos": [0, 0], "gnss_vel": [0, 0]}    # [used, rejected]
        self.events: list[dict] = []

    def _use_fixes(self, G, gi: int, sol: NavSolution, w: np.ndarray) -> tuple[int, NavSolution]:
        """Use the fixes of G from ``gi`` valid by ``sol.t_s``; returns (next fix, solution)."""
        t = sol.t_s
        while gi < len(G) and G[gi, 0] <= t + 1e-9:
            groups = self.filter.gnss_update(_fix(G[gi], sol, t, self.gnss), sol, _w_eb(sol, w))
            for g in groups:
                self.counts[g.name][0 if g.used else 1] += 1
                if g.reset:
                    self.events.append({"t_s": round(t, 3), "kind": "gate_reset",
                                        "group": g.name})
            if any(g.used for g in groups):
                dx = self.filter.take_feedback()
                correct_row(self.row, np.ascontiguousarray(dx[:9]), _NO_LEVER, w)
                self.comp += dx[9:15]
                sol = row_solution(self.row, t)
            gi += 1
        return gi, sol

    def _record(self, sol: NavSolution) -> list[float]:
        P = self.filter.P
        sd_att = euler_sigma_rad(P[6:9, 6:9], sol.pitch_rad, sol.heading_rad)
        v = sol.v_enu_mps
        sd = np.sqrt(np.maximum(np.diag(P)[:6], 0.0))
        return [sol.t_s, math.degrees(sol.lat_rad), math.degrees(sol.lon_rad), sol.alt_m, v[1],
                v[0], -v[2], math.degrees(sol.roll_rad), math.degrees(sol.pitch_rad),
                math.degrees(sol.heading_rad), sd[1], sd[0], sd[2], sd[4], sd[3], sd[5],
                *np.degrees(sd_att), *(self.comp[:3] / G0_MPS2 * 1e6),
                *(self.comp[3:] / DPH_RPS)]

    def run(self, t: np.ndarray, inc: np.ndarray, G: np.ndarray) -> pd.DataFrame:
        """Replay the increments ``inc`` (n-1, 6) at the times ``t`` (n,) s with the GNSS rows
        ``G`` (:func:`~.replay_io.read_gnss`); returns the solution at every navigation step
        (:data:`OUT_COLS`, :data:`SIGMA_COLS`, :data:`BIAS_COLS`)."""
        t = np.ascontiguousarray(t, float)
        inc = np.ascontiguousarray(inc, float)
        sol = row_solution(self.row, float(t[0]))
        initial_covariance(self.filter, sol, self.init)
        gi = int(np.searchsorted(G[:, 0], t[0] - 1e-9))
        n = len(inc)
        per = max(1, int(round(self.nav_dt_s / float(np.median(np.diff(t))))))
        out = [self._record(sol)]
        k = 0
        while k < n:
            j = min(k + per, n)
            if gi < len(G) and G[gi, 0] <= t[j]:
                j = max(int(np.searchsorted(t, G[gi, 0] - 1e-9)), k + 1)
            s, w = mechanise_span(self.row, inc, t, k, j, self.comp)
            T = t[j] - t[k]
            self.filter.predict(sol, s[:3] / T, s[3:] / T, T)
            sol = row_solution(self.row, float(t[j]))
            gi, sol = self._use_fixes(G, gi, sol, w)
            out.append(self._record(sol))
            k = j
        return pd.DataFrame(out, columns=list(OUT_COLS + SIGMA_COLS + BIAS_COLS))


def error_table(sol: pd.DataFrame, truth: np.ndarray) -> pd.DataFrame:
    """Solution minus truth at the solution's times inside the truth's span (truth linearly
    interpolated, heading unwrapped): ``t_s``, ``err_north_m``, ``err_east_m``, ``err_alt_m``,
    ``err_vn_mps``, ``err_ve_mps``, ``err_vd_mps``, ``err_roll_deg``, ``err_pitch_deg``,
    ``err_heading_deg``, ``err_horizontal_m``.

    Parameters
    ----------
    sol : :meth:`Replay.run`'s table;  truth : (m, 10) rows of :data:`~.replay_io.PVA_COLS`
    """
    ts = sol["t_s"].to_numpy()
    keep = (ts >= truth[0, 0]) & (ts <= truth[-1, 0])
    s = sol[keep]
    ts = ts[keep]
    tr = {}
    for j, c in enumerate(("lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "heading")):
        y = truth[:, j + 1]
        if c in ("roll", "heading"):
            y = np.degrees(np.unwrap(np.radians(y)))
        tr[c] = np.interp(ts, truth[:, 0], y)
    lat = np.radians(tr["lat"])
    rm, rn = radii_m(lat)
    d_n = np.radians(s["nav_lat_deg"].to_numpy() - tr["lat"]) * (rm + tr["alt"])
    d_e = np.radians(s["nav_lon_deg"].to_numpy() - tr["lon"]) * (rn + tr["alt"]) * np.cos(lat)

    def ang(a, b):
        return (a - b + 180.0) % 360.0 - 180.0
    return pd.DataFrame({
        "t_s": ts, "err_north_m": d_n, "err_east_m": d_e,
        "err_alt_m": s["nav_alt_m"].to_numpy() - tr["alt"],
        "err_vn_mps": s["nav_vn_mps"].to_numpy() - tr["vn"],
        "err_ve_mps": s["nav_ve_mps"].to_numpy() - tr["ve"],
        "err_vd_mps": s["nav_vd_mps"].to_numpy() - tr["vd"],
        "err_roll_deg": ang(s["nav_roll_deg"].to_numpy(), tr["roll"]),
        "err_pitch_deg": s["nav_pitch_deg"].to_numpy() - tr["pitch"],
        "err_heading_deg": ang(s["nav_heading_deg"].to_numpy(), tr["heading"]),
        "err_horizontal_m": np.hypot(d_n, d_e)})


_ERR_SIGMA = (("err_north_m", "nav_north_sigma_m"), ("err_east_m", "nav_east_sigma_m"),
              ("err_alt_m", "nav_alt_sigma_m"), ("err_vn_mps", "nav_vn_sigma_mps"),
              ("err_ve_mps", "nav_ve_sigma_mps"), ("err_vd_mps", "nav_vd_sigma_mps"),
              ("err_roll_deg", "nav_roll_sigma_deg"), ("err_pitch_deg", "nav_pitch_sigma_deg"),
              ("err_heading_deg", "nav_heading_sigma_deg"))


def error_stats(err: pd.DataFrame, sol: pd.DataFrame) -> dict:
    """Summary statistics of :func:`error_table`: horizontal error 50/95 % and max (m), RMS of
    every error, and RMS(error/σ) per state over the samples with σ > 0 (1 for an honest
    covariance; pyins' tests ask < 1.5).

    Parameters
    ----------
    err : :func:`error_table`'s result;  sol : the solution table it was made from
    """
    sig = sol.set_index("t_s").loc[err["t_s"]]
    h = err["err_horizontal_m"].to_numpy()
    out = {"samples": int(len(err)),
           "horizontal_m": {"p50": round(float(np.percentile(h, 50)), 3),
                            "p95": round(float(np.percentile(h, 95)), 3),
                            "max": round(float(h.max()), 3)},
           "rms": {}, "rms_error_over_sigma": {}}
    for e, s in _ERR_SIGMA:
        x = err[e].to_numpy()
        out["rms"][e[4:]] = round(float(np.sqrt(np.mean(x ** 2))), 4)
        sd = sig[s].to_numpy()
        z = x[sd > 0] / sd[sd > 0]          # the start may be known exactly (σ 0)
        out["rms_error_over_sigma"][e[4:]] = round(float(np.sqrt(np.mean(z ** 2))), 3)
    return out


def solution_minus_flight(sol: pd.DataFrame, flight: pd.DataFrame) -> pd.DataFrame:
    """A replayed solution minus a flight's own navigation solution, at the replay's times that
    the flight's log also holds (within 1 µs): ``t_s``, ``d_north_m``, ``d_east_m``,
    ``d_horizontal_m``, ``d_alt_m``, ``d_heading_deg`` (wrapped to ±180°).

    The flight log's ``nav_alt_m`` is JSBSim's sea-level height; the replay's is ellipsoidal
    (WGS-84), so the flight's is converted (:func:`~fms_testbed.core.earth.ellipsoidal_height_m`)
    before the difference. North/east are arcs on the meridian/prime-vertical radii at the
    flight's latitude.

    Parameters
    ----------
    sol : :meth:`Replay.run`'s table (``t_s``, ``nav_lat_deg``, ``nav_lon_deg``, ``nav_alt_m``,
        ``nav_heading_deg``)
    flight : the flight's log as a table (:meth:`Results.to_pandas`), same column names
    """
    s = sol.drop_duplicates("t_s").set_index("t_s")
    fl = flight.drop_duplicates("t_s").set_index("t_s")
    ft = fl.index.to_numpy()
    j = np.clip(np.searchsorted(ft, s.index.to_numpy()), 1, len(ft) - 1)
    j = np.where(np.abs(ft[j - 1] - s.index.to_numpy()) < np.abs(ft[j] - s.index.to_numpy()),
                 j - 1, j)
    same = np.abs(ft[j] - s.index.to_numpy()) < 1e-6
    s, f = s[same], fl.iloc[j[same]]
    lat = np.radians(f["nav_lat_deg"].to_numpy())
    rm, rn = radii_m(lat)
    d_n = np.radians(s["nav_lat_deg"].to_numpy() - f["nav_lat_deg"].to_numpy()) * rm
    d_e = np.radians(s["nav_lon_deg"].to_numpy() - f["nav_lon_deg"].to_numpy()) * rn * np.cos(lat)
    h = np.array([ellipsoidal_height_m(a, b) for a, b in zip(lat, f["nav_alt_m"].to_numpy())])
    d_psi = (s["nav_heading_deg"].to_numpy() - f["nav_heading_deg"].to_numpy() + 180.0) \
        % 360.0 - 180.0
    return pd.DataFrame({"t_s": s.index.to_numpy(), "d_north_m": d_n, "d_east_m": d_e,
                         "d_horizontal_m": np.hypot(d_n, d_e),
                         "d_alt_m": s["nav_alt_m"].to_numpy() - h, "d_heading_deg": d_psi})


__all__ = ["BIAS_COLS", "OUT_COLS", "Replay", "SIGMA_COLS", "error_stats", "error_table",
           "euler_sigma_rad", "initial_covariance", "initial_row", "mechanise_span",
           "row_solution", "solution_minus_flight"]
