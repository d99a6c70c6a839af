"""JSBSim aircraft: side-effect-free loading, trim, cached property access, inner-loop commands.

Loading copies the wheel's model folder into a private temporary folder and strips every
top-level ``<input>`` (telnet/UDP sockets) and ``<output>`` (CSV/socket logging) element, then
adds the inner-loop ``<system>`` (:mod:`fms_testbed.sim.inner_loops`). The temporary folder is removed
when the process ends (or :func:`cleanup` is called). JSBSim's console output is routed to the
``jsbsim`` Python logger.
"""

from __future__ import annotations

import atexit
import logging
import math
import shutil
import tempfile
import threading
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import jsbsim
import numpy as np

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.errors import TrimError, UserError
from fms_testbed.sim.inner_loops import gain_properties, system_xml
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import (DEG_RAD, FT_M, KT_MPS, LBF_N, PSF_PA, RANKINE_K, SLUG_KG,
                                    mps_to_kmh)

log = logging.getLogger("fms_testbed.jsbsim")

DT_S = 1.0 / 120.0

# ----------------------------------------------------------------------------------- logging


class _PyLogger(jsbsim.FGLogger):
    """Route JSBSim log records to the ``jsbsim`` Python logger."""

    _LEVELS = {0: logging.DEBUG, 1: logging.DEBUG, 2: logging.DEBUG, 3: logging.WARNING,
               4: logging.ERROR, 5: logging.CRITICAL, 6: logging.DEBUG}

    def __init__(self):
        super().__init__()
        self._level = logging.DEBUG
        self._buf: list[str] = []
        self._logger = logging.getLogger("jsbsim")

    def set_level(self, level):
        self._level = self._LEVELS.get(int(level), logging.DEBUG)
        self._buf = []

    def file_location(self, filename, line):
        self._buf.append(f"{filename}:{line}: ")

    def message(self, message):
        self._buf.append(message)

    def format(self, format):  # noqa: A002 - JSBSim's name
        pass

    def flush(self):
        text = "".join(self._buf).strip()
        self._buf = []
        if text:
            self._logger.log(self._level, "%s", text)


_tls = threading.local()


def _install_logger() -> None:
    if not getattr(_tls, "logger", None):
        _tls.logger = _PyLogger()
        jsbsim.set_logger(_tls.logger)


# ------------------------------------------------------------------------------ sanitising

_sandbox_lock = threading.Lock()
_sandbox: tempfile.TemporaryDirectory | None = None


def _sandbox_dir() -> Path:
    global _sandbox
    with _sandbox_lock:
        if _sandbox is None:
            _sandbox = tempfile.TemporaryDirectory(prefix="fms-testbed-jsbsim-")
            atexit.register(cleanup)
        return Path(_sandbox.name)


def cleanup() -> None:
    """Remove the private folder of sanitised aircraft definitions."""
    global _sandbox
    with _sandbox_lock:
        if _sandbox is not None:
            _sandbox.cleanup()
            _sandbox = None


def has_piston_engines(model: str) -> bool:
    """Whether the wheel's model ``model`` is powered by JSBSim piston engines.

    Reads each ``<engine file=…>`` of the model and the root element of that engine file
    (``<piston_engine>``) in the package's ``engine`` folder or the model's own ``Engines``.
    """
    root_dir = Path(jsbsim.get_default_root_dir())
    root = ET.parse(root_dir / "aircraft" / model / f"{model}.xml").getroot()
    for el in root.findall("./propulsion/engine"):
        name = el.get("file", "")
        for folder in (root_dir / "engine", root_dir / "aircraft" / model / "Engines"):
            f = folder / f"{name}.xml"
            if f.exists():
                if ET.parse(f).getroot().tag == "piston_engine":
                    return True
                break
    return False


BALLAST_XML = ('<pointmass name="fms-ballast"><weight unit="LBS">0</weight>'
               '<location unit="IN"><x>0</x><y>0</y><z>0</z></location></pointmass>')
"""The point mass every sanitised model carries (weight 0: no effect until a design point
sets its weight and position, :func:`fms_testbed.sim.linearise.set_mass_and_cg`)."""


def sanitized_aircraft_path(model: str, elevator_rate_max_ps: float | None,
                            frames_per_update: int = 1) -> Path:
    """Copy ``model`` from the jsbsim wheel into the sandbox without I/O elements.

    Returns the sandbox's ``aircraft`` folder (to pass to ``set_aircraft_path``). Removes every
    top-level ``<input>`` and ``<output>`` element, adds the zero-weight ballast point mass
    (:data:`BALLAST_XML`) and appends the inner-loop ``<system>``
    (not when ``elevator_rate_max_ps`` is None: the bare model, for benchmarks), updated every
    ``frames_per_update`` frames.
    """
    src = Path(jsbsim.get_default_root_dir()) / "aircraft" / model
    if not (src / f"{model}.xml").exists():
        raise UserError(f"JSBSim model '{model}' is not in the jsbsim package's aircraft folder")
    key = (f"{model}-er{elevator_rate_max_ps:g}-x{frames_per_update}" if elevator_rate_max_ps
           else f"{model}-bare")
    dst_root = _sandbox_dir() / key
    dst = dst_root / model
    if (dst / f"{model}.xml").exists():
        return dst_root
    shutil.copytree(src, dst, dirs_exist_ok=True)
    tree = ET.parse(src / f"{model}.xml")
    root = tree.getroot()
    removed = 0
    for tag in ("input", "output"):
        for el in root.findall(tag):
            root.remove(el)
            removed += 1
    n_eng = len(root.findall("./propulsion/engine"))
    mb = root.find("mass_balance")
    if mb is not None:     # zero-weight ballast, moved by design points for CG shifts
        mb.append(ET.fromstring(BALLAST_XML))
    if elevator_rate_max_ps:
        root.append(ET.fromstring(system_xml(n_eng, elevator_rate_max_ps, DT_S, frames_per_update,
                                             piston=has_piston_engines(model))))
    tree.write(dst / f"{model}.xml", encoding="utf-8", xml_declaration=True)
    log.debug("sanitised %s: removed %d I/O elements, %d engines", model, removed, n_eng)
    return dst_root


def bare_fdm(model: str, dt_s: float = DT_S) -> "jsbsim.FGFDMExec":
    """A sanitised JSBSim instance of ``model`` without the inner loops (for benchmarks)."""
    _install_logger()
    fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir())
    fdm.set_debug_level(0)
    fdm.disable_output()
    fdm.set_dt(dt_s)
    fdm.set_aircraft_path(str(sanitized_aircraft_path(model, None)))
    if not fdm.load_model(model):
        raise UserError(f"JSBSim could not load model '{model}'")
    fdm.set_dt(dt_s)
    return fdm


# --------------------------------------------------------------------------------- model


@dataclass(frozen=True)
class TrimResult:
    """Trimmed condition: control positions and angles (SI/normalised)."""

    alt_m: float
    tas_mps: float
    alpha_deg: float
    pitch_deg: float
    throttle: float
    elevator: float
    aileron: float
    rudder: float


_READ = {  # state field -> (property, scale)
    "t_s": ("simulation/sim-time-sec", 1.0),
    "lat_deg": ("position/lat-geod-deg", 1.0),
    "lon_deg": ("position/long-gc-deg", 1.0),
    "alt_m": ("position/h-sl-ft", FT_M),
    "agl_m": ("position/h-agl-ft", FT_M),
    "tas_mps": ("velocities/vt-fps", FT_M),
    "cas_mps": ("velocities/vc-kts", KT_MPS),
    "gs_mps": ("velocities/vg-fps", FT_M),
    "vs_mps": ("velocities/h-dot-fps", FT_M),
    "vn": ("velocities/v-north-fps", FT_M),
    "ve": ("velocities/v-east-fps", FT_M),
    "vd": ("velocities/v-down-fps", FT_M),
    "roll_rad": ("attitude/phi-rad", 1.0),
    "pitch_rad": ("attitude/theta-rad", 1.0),
    "heading_rad": ("attitude/psi-rad", 1.0),
    "track_rad": ("flight-path/psi-gt-rad", 1.0),
    "alpha_rad": ("aero/alpha-rad", 1.0),
    "beta_rad": ("aero/beta-rad", 1.0),
    "gamma_rad": ("flight-path/gamma-rad", 1.0),
    "p_rps": ("velocities/p-rad_sec", 1.0),
    "q_rps": ("velocities/q-rad_sec", 1.0),
    "r_rps": ("velocities/r-rad_sec", 1.0),
    "weight_lbs": ("inertia/weight-lbs", 1.0),
    "fx": ("forces/fbx-total-lbs", LBF_N),
    "fy": ("forces/fby-total-lbs", LBF_N),
    "fz": ("forces/fbz-total-lbs", LBF_N),
    "mach": ("velocities/mach", 1.0),
    "throttle": ("fms/throttle-out", 1.0),
    "mass_kg": ("inertia/mass-slugs", SLUG_KG),
    "elevator": ("fcs/elevator-cmd-norm", 1.0),
    "aileron": ("fcs/aileron-cmd-norm", 1.0),
    "rudder": ("fcs/rudder-cmd-norm", 1.0),
    "wow": ("gear/wow", 1.0),
    "flap_pos_norm": ("fcs/flap-pos-norm", 1.0),
    "gear_pos_norm": ("gear/gear-pos-norm", 1.0),
    "p_static_pa": ("atmosphere/P-psf", PSF_PA),
    "t_static_k": ("atmosphere/T-R", RANKINE_K),
}


def wind_axis_load_factors(fx_lbs, fz_lbs, alpha_rad, weight_lbs, cos=math.cos, sin=math.sin):
    """Tangential and normal load factors (g) from JSBSim's total body forces, gravity excluded:
    ``n_x = (F_x cos α + F_z sin α) / W``, ``n_y = (F_x sin α - F_z cos α) / W`` (coupled-law note,
    an accelerometer along the wind axes). Scalars with ``math`` (default) or arrays with
    ``cos=np.cos, sin=np.sin``."""
    ca, sa = cos(alpha_rad), sin(alpha_rad)
    return (fx_lbs * ca + fz_lbs * sa) / weight_lbs, (fx_lbs * sa - fz_lbs * ca) / weight_lbs


def raw_to_si(raw: np.ndarray) -> dict[str, np.ndarray]:
    """Columns of stacked :meth:`JSBSimAircraft.read_raw` rows (shape (n, len(_READ))) in SI,
    keyed like ``_READ``, plus ``nx`` and ``ny`` (g) — the vectorised twin of
    :meth:`JSBSimAircraft.state`, used to build the logged timeseries at the end of a run."""
    raw = np.asarray(raw, dtype=float).reshape(-1, len(_READ))
    out = {k: raw[:, i] * sc for i, (k, (_, sc)) in enumerate(_READ.items())}
    r = {k: raw[:, i] for i, k in enumerate(_READ)}
    out["nx"], out["ny"] = wind_axis_load_factors(r["fx"], r["fz"], r["alpha_rad"],
                                                  r["weight_lbs"], np.cos, np.sin)
    return out


#: Position of each ``_READ`` field in a :meth:`JSBSimAircraft.read_raw` list.
RAW = {k: i for i, k in enumerate(_READ)}
# the order JSBSimAircraft.state unpacks (a test keeps the two in step)
_STATE_ORDER = ("t_s", "lat_deg", "lon_deg", "alt_m", "agl_m", "tas_mps", "cas_mps", "gs_mps",
                "vs_mps", "vn", "ve", "vd", "roll_rad", "pitch_rad", "heading_rad", "track_rad",
                "alpha_rad", "beta_rad", "gamma_rad", "p_rps", "q_rps", "r_rps", "weight_lbs",
                "fx", "fy", "fz", "mach", "throttle", "mass_kg", "elevator", "aileron", "rudder",
                "wow", "flap_pos_norm", "gear_pos_norm", "p_static_pa", "t_static_k")


class InnerLoopCommands:
    """The inner-loop and configuration commands of :class:`JSBSimAircraft` (its ``fdm`` and the
    cached property nodes ``_w``, ``_setters``, ``_w_flap``, ``_w_gear`` that ``_load`` makes)."""

    def hold_trim(self, res: TrimResult) -> TrimResult:
        """Make ``res`` the state the inner loops start from: its control positions as their
        trim offsets, its throttle as the command, wings level at 1 g, the loops engaged; and
        the start condition the flight summary reports (:meth:`trim_result`)."""
        fdm = self.fdm
        fdm["fms/trim/elevator"] = res.elevator
        fdm["fms/trim/aileron"] = res.aileron
        fdm["fms/trim/rudder"] = res.rudder
        fdm["fms/trim/throttle"] = res.throttle
        fdm["fms/cmd/throttle"] = res.throttle
        fdm["fms/cmd/bank-rad"] = 0.0
        fdm["fms/cmd/ny"] = 1.0
        fdm["fms/cmd/nx"] = 0.0
        fdm["fms/ap/master"] = 1.0
        self._trim = res
        return res

    def engage(self, bank: bool = True, yaw: bool = True, ny: bool = True, nx: bool = True) -> None:
        """Engage (or release) the inner loops."""
        w = self._w
        for loop, on in (("bank", bank), ("yaw", yaw), ("ny", ny)):
            w[f"fms/ap/{loop}-engage"].set_double_value(float(on))
            # JSBSim pid trigger: 0 integrates, < 0 resets the integrator
            w[f"fms/ap/{loop}-trigger"].set_double_value(0.0 if on else -1.0)
        w["fms/ap/nx-engage"].set_double_value(float(nx))

    def command(self, bank_rad: float | None = None, ny: float | None = None,
                nx: float | None = None, throttle: float | None = None) -> None:
        """Set inner-loop targets: bank (rad), normal/tangential load factor (g), throttle (0..1).

        A throttle command disengages the n_x loop; an n_x command engages it.
        """
        set_bank, set_ny, set_nx, set_thr, set_nx_engage = self._setters
        if bank_rad is not None:
            set_bank(bank_rad)
        if ny is not None:
            set_ny(ny)
        if nx is not None:
            set_nx(nx)
            set_nx_engage(1.0)
        if throttle is not None:
            set_thr(throttle)
            set_nx_engage(0.0)

    def configure(self, flap_cmd_norm: float | None = None,
                  gear_down: bool | None = None) -> None:
        """Select a flap detent (``fcs/flap-cmd-norm``, the model's normalised flap command;
        the model's kinematic moves the flaps at its own rate) and/or the gear
        (``gear/gear-cmd-norm`` 1 down, 0 up); None leaves a control as it is."""
        if flap_cmd_norm is not None:
            self._w_flap.set_double_value(float(flap_cmd_norm))
        if gear_down is not None:
            self._w_gear.set_double_value(1.0 if gear_down else 0.0)


class JSBSimAircraft(InnerLoopCommands):
    """One JSBSim instance flying one aircraft at 120 Hz, with the inner loops installed.

    Parameters
    ----------
    cfg : aircraft configuration (model, limits, gains)
    dt_s : frame time, s (default 1/120)
    """

    def __init__(self, cfg: AircraftConfig, dt_s: float = DT_S):
        _install_logger()
        self.cfg = cfg
        self.dt_s = dt_s
        self._trim: TrimResult | None = None
        self.isa_dev_c = 0.0
        self._load()

    def _load(self) -> None:
        """(Re)create the JSBSim instance and cache the property nodes."""
        cfg, dt_s = self.cfg, self.dt_s
        root = jsbsim.get_default_root_dir()
        ac_path = sanitized_aircraft_path(cfg.jsbsim_model, cfg.inner_loops.elevator_rate_max_ps,
                                          cfg.inner_loops.frames_per_update)
        fdm = jsbsim.FGFDMExec(root)
        fdm.set_debug_level(0)
        fdm.disable_output()
        # before loading: JSBSim's FCS components take their step (frame time x channel rate)
        # when they are built
        fdm.set_dt(dt_s)
        fdm.set_aircraft_path(str(ac_path))
        if not fdm.load_model(cfg.jsbsim_model):
            raise UserError(f"JSBSim could not load model '{cfg.jsbsim_model}' for aircraft {cfg.name}")
        fdm.set_dt(dt_s)
        self.fdm = fdm
        self.n_engines = fdm.get_propulsion().get_num_engines()
        pm = fdm.get_property_manager()
        self._nodes = {k: pm.get_node(p, False) for k, (p, _) in _READ.items()}
        missing = [_READ[k][0] for k, n in self._nodes.items() if n is None]
        if missing:
            raise UserError(f"{cfg.jsbsim_model}: JSBSim properties missing: {missing}")
        self._keys = tuple(_READ)
        self._getters = tuple((self._nodes[k].get_double_value, sc) for k, (_, sc) in _READ.items())
        self._raw_getters = tuple(g for g, _ in self._getters)
        self._w = {name: pm.get_node(name, True) for name in (
            "fms/ap/bank-engage", "fms/ap/yaw-engage", "fms/ap/ny-engage", "fms/ap/nx-engage",
            "fms/ap/bank-trigger", "fms/ap/yaw-trigger", "fms/ap/ny-trigger",
            "fms/cmd/bank-rad", "fms/cmd/ny", "fms/cmd/nx", "fms/cmd/throttle")}
        self._setters = tuple(self._w[k].set_double_value for k in (
            "fms/cmd/bank-rad", "fms/cmd/ny", "fms/cmd/nx", "fms/cmd/throttle", "fms/ap/nx-engage"))
        self._w_flap = pm.get_node("fcs/flap-cmd-norm", True)
        self._w_gear = pm.get_node("gear/gear-cmd-norm", True)
        self._write_gains()

    # -- properties ------------------------------------------------------------------
    def __getitem__(self, name: str) -> float:
        return self.fdm[name]

    def __setitem__(self, name: str, value: float) -> None:
        self.fdm[name] = value

    def set_gains(self, cfg: AircraftConfig) -> None:
        """Use the inner-loop gains of ``cfg`` (same JSBSim model) from now on."""
        self.cfg = cfg
        self._write_gains()

    def _write_gains(self) -> None:
        for prop, val in gain_properties(self.cfg).items():
            self.fdm[prop] = float(val)

    # -- atmosphere and wind (the day's conditions) --------------------------------------
    def set_isa_dev(self, isa_dev_c: float) -> None:
        """Fly a day ``isa_dev_c`` (K) off the ISA: JSBSim's ``atmosphere/delta-T`` (°R, the
        temperature bias over the whole standard profile; sea-level pressure kept, pressure
        hydrostatic through the biased temperature — :mod:`fms_testbed.core.atmosphere`).
        Kept across a re-load (trim retry) and set before every trim."""
        self.isa_dev_c = float(isa_dev_c)
        self.fdm["atmosphere/delta-T"] = self.isa_dev_c * 1.8

    # -- trim ------------------------------------------------------------------------
    def trim(self, alt_m: float, tas_mps: float, heading_deg: float = 0.0,
             lat_deg: float = 45.0, lon_deg: float = 0.0, gamma_deg: float = 0.0,
             terrain_elev_m: float = 0.0, flap_cmd_norm: float = 0.0,
             gear_down: bool = False) -> TrimResult:
        """Trim in steady straight flight in calm air; raise :class:`TrimError` naming aircraft and
        condition (JSBSim 1.3.3 cannot trim in wind: the runner ramps the wind in afterwards).

        Bounded alpha search (``trim.alpha_max_deg``), engines running, gear up unless
        ``gear_down``, flaps at ``flap_cmd_norm`` (``fcs/flap-cmd-norm``, already extended),
        the terrain at ``terrain_elev_m`` above mean sea level (``ic/terrain-elevation-ft``:
        height above ground and ground contact are then relative to it, m). JSBSim's trim
        sometimes fails from the state a previous run left (engine and FCS internals survive
        ``run_ic``); a failure is retried once on a freshly loaded instance before it is reported.
        """
        args = (alt_m, tas_mps, heading_deg, lat_deg, lon_deg, gamma_deg, terrain_elev_m,
                flap_cmd_norm, gear_down)
        if self.fdm.get_sim_time() > 0.0:
            try:
                return self._trim_once(*args)
            except TrimError:
                log.debug("trim retried on a fresh JSBSim instance")
                self._load()
        return self._trim_once(*args)

    def _trim_once(self, alt_m, tas_mps, heading_deg, lat_deg, lon_deg, gamma_deg,
                   terrain_elev_m=0.0, flap_cmd_norm=0.0, gear_down=False):
        fdm, c = self.fdm, self.cfg
        cond = (f"{c.name} ({c.jsbsim_model}) at {alt_m:.0f} m / {mps_to_kmh(tas_mps):.0f} km/h TAS, "
                f"gamma {gamma_deg:.1f} deg")
        fdm["atmosphere/delta-T"] = self.isa_dev_c * 1.8   # a re-loaded instance: again
        fdm["ic/lat-geod-deg"] = lat_deg
        fdm["ic/long-gc-deg"] = lon_deg
        fdm["ic/terrain-elevation-ft"] = terrain_elev_m / FT_M
        fdm["ic/h-sl-ft"] = alt_m / FT_M
        fdm["ic/vt-kts"] = tas_mps / KT_MPS
        fdm["ic/psi-true-deg"] = heading_deg
        fdm["ic/gamma-deg"] = gamma_deg
        fdm["ic/phi-deg"] = 0.0
        for comp in ("north", "east", "down"):
            fdm[f"atmosphere/wind-{comp}-fps"] = 0.0
        fdm["aero/alpha-max-rad"] = math.radians(c.trim.alpha_max_deg)
        fdm["aero/alpha-min-rad"] = math.radians(c.trim.alpha_min_deg)
        fdm["fms/ap/master"] = 0.0
        for name in ("fms/ap/bank-engage", "fms/ap/yaw-engage", "fms/ap/ny-engage", "fms/ap/nx-engage"):
            fdm[name] = 0.0
        for name in ("fms/ap/bank-trigger", "fms/ap/yaw-trigger", "fms/ap/ny-trigger"):
            fdm[name] = -1.0
        for prop, val in (("fcs/elevator-cmd-norm", 0.0), ("fcs/aileron-cmd-norm", 0.0),
                          ("fcs/rudder-cmd-norm", 0.0), ("fcs/pitch-trim-cmd-norm", 0.0)):
            fdm[prop] = val
        for i in range(self.n_engines):
            fdm[f"fcs/throttle-cmd-norm[{i}]"] = 0.5
        fdm["gear/gear-cmd-norm"] = 1.0 if gear_down else 0.0
        fdm["gear/gear-pos-norm"] = 1.0 if gear_down else 0.0
        fdm["fcs/flap-cmd-norm"] = flap_cmd_norm
        fdm["fcs/flap-pos-norm"] = flap_cmd_norm
        for i in range(self.n_engines):
            fdm[f"fcs/mixture-cmd-norm[{i}]"] = 1.0
            fdm[f"fcs/advance-cmd-norm[{i}]"] = 1.0
        if not fdm.run_ic():
            raise TrimError(f"JSBSim rejected the initial condition: {cond}")
        fdm["propulsion/set-running"] = -1
        try:
            fdm["simulation/do_simple_trim"] = 1
        except jsbsim.TrimFailureError as exc:
            raise TrimError(f"trim failed for {cond}: {str(exc).strip() or 'no convergence'}") from None
        except RuntimeError as exc:
            raise TrimError(f"trim failed for {cond}: {str(exc).strip()}") from None
        alpha = math.degrees(fdm["aero/alpha-rad"])
        if not math.isfinite(alpha) or alpha > c.trim.alpha_max_deg + 0.5:
            raise TrimError(f"trim failed for {cond}: alpha {alpha:.1f} deg beyond bound")
        thr = fdm["fcs/throttle-cmd-norm[0]"]
        res = TrimResult(alt_m=alt_m, tas_mps=fdm["velocities/vt-fps"] * FT_M, alpha_deg=alpha,
                         pitch_deg=math.degrees(fdm["attitude/theta-rad"]), throttle=thr,
                         elevator=fdm["fcs/elevator-cmd-norm"], aileron=fdm["fcs/aileron-cmd-norm"],
                         rudder=fdm["fcs/rudder-cmd-norm"])
        if not (c.inner_loops.throttle_min - 1e-6 <= thr <= c.inner_loops.throttle_max + 1e-6):
            raise TrimError(f"trim failed for {cond}: throttle {thr:.2f} outside "
                            f"[{c.inner_loops.throttle_min}, {c.inner_loops.throttle_max}]")
        return self.hold_trim(res)

    @property
    def trim_result(self) -> TrimResult | None:
        """The last trim, or ``None``."""
        return self._trim

    # -- stepping and state ----------------------------------------------------------------
    def run(self, n_steps: int = 1) -> bool:
        """Advance ``n_steps`` frames; return False if JSBSim stops."""
        run = self.fdm.run
        for _ in range(n_steps):
            if not run():
                return False
        return True

    def frame_getters(self, properties) -> tuple:
        """Cached getters for ``(property, scale to SI)`` pairs, for :meth:`run_sampled`.

        Raises
        ------
        UserError
            When the model lacks one of the properties (named)."""
        pm = self.fdm.get_property_manager()
        nodes = [(pm.get_node(p, False), p) for p, _ in properties]
        missing = [p for n, p in nodes if n is None]
        if missing:
            raise UserError(f"{self.cfg.jsbsim_model}: JSBSim properties missing: {missing}")
        return tuple((n.get_double_value, float(sc)) for (n, _), (_, sc) in zip(nodes, properties))

    def run_sampled(self, n_steps: int, getters: tuple, out: np.ndarray) -> bool:
        """Advance ``n_steps`` frames, reading ``getters`` (:meth:`frame_getters`) after each
        one into row ``i`` of ``out`` (shape at least ``(n_steps, len(getters))``, SI); return
        False if JSBSim stops (the rows after the stop are left as they were)."""
        run = self.fdm.run
        for i in range(n_steps):
            if not run():
                return False
            row = out[i]
            for j, (g, sc) in enumerate(getters):
                row[j] = g() * sc
        return True

    def read_raw(self) -> list[float]:
        """Read every property of ``_READ`` through its cached node, in JSBSim's units, in
        ``_READ`` order (index with :data:`RAW`); the hot path's one read per outer step."""
        return [g() for g in self._raw_getters]

    def state(self, raw: list[float] | None = None) -> AircraftState:
        """Return the true state as an :class:`AircraftState` (SI) from a :meth:`read_raw`
        list (read now when ``raw`` is None)."""
        (t, lat, lon, h, agl, vt, vc, vg, hdot, vn, ve, vd, phi, theta, psi, trk, alpha, beta,
         gamma, p, q, r, w_lbs, fx, fy, fz, mach, thr, m_slug, _e, _a, _r, _w, _f, _g, ps, ts) = (
            raw if raw is not None else self.read_raw())
        rad = DEG_RAD
        k = LBF_N / (m_slug * SLUG_KG)
        # from this frame's forces (the inner loops' own measurement runs at the loop rate)
        nx, ny = wind_axis_load_factors(fx, fz, alpha, w_lbs)
        # positional, in AircraftState's field order (cheaper than keywords on the hot path)
        return AircraftState(
            t, lat * rad, lon * rad, h * FT_M, vt * FT_M, vc * KT_MPS, vg * FT_M, hdot * FT_M,
            np.array((ve * FT_M, vn * FT_M, -vd * FT_M)), phi, theta, psi, trk, alpha, beta, gamma,
            p, q, r, nx, ny, np.array((fx * k, fy * k, fz * k)), mach, agl * FT_M, thr,
            m_slug * SLUG_KG, ps * PSF_PA, ts * RANKINE_K)
