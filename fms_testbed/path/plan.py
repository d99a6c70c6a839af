"""What to fly: the scenario's ``procedure:`` block, selection of the ARINC-424 sequences that
make one flyable procedure, and (re)building it into a :class:`ProcedurePath`.

A flyable procedure is the concatenation of the database's transitions, in flying order:

* SID:  runway transition (``RWxx`` / ``RWxxB``) → common route → en-route transition
* STAR: en-route transition → common route → runway transition
* approach: approach transition (route type ``A``) → final approach, cut at the missed-approach
  point (an approach ends at the runway/MAP: the flight stops there) unless the missed
  approach is flown (``procedure.missed``): then its legs follow, to the end of the first
  holding circuit

The ``IF`` that starts a later part is dropped when it repeats the fix the previous part ends at;
after a transition that ends in a hold at a fix the next part reaches later, the next part is
joined at that fix.
The path itself comes from the issue-4 builder (``arinc424.segmentation.build_sequence``) and
monitor (``arinc424.monitor.check_path``); :func:`rebuild_from` builds the rest of a procedure
from the aircraft's actual state when a conditional leg ends in flight.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from fms_testbed.config.procedure import ProcedureSpec, parse_procedure  # noqa: F401 (re-export)
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.profile import PLAN_CLIMB_FRACTION  # noqa: F401 (re-export)



def load_db(spec_db: str, base: Path | None = None):
    """Load an ARINC-424 database ('embedded' = the excerpt in ``fms_testbed/data/procedures/``);
    a relative path is relative to ``base`` (the scenario file's folder) when one is given."""
    from fms_testbed.procedures.database import load_database

    if spec_db in ("", "embedded"):
        return load_database(None)
    p = Path(spec_db)
    if not p.is_absolute() and base is not None:
        p = base / p
    return load_database(p)


def _is_rw(t: str) -> bool:
    return t.startswith("RW")


def _runway_match(trans: str, runway: str) -> bool:
    rw = runway if runway.startswith("RW") else "RW" + runway
    if trans == rw:
        return True
    # 'RW16B' serves 16L/16C/16R
    return trans.endswith("B") and rw[:-1] == trans[:-1] and rw[-1] in "LRC"


def select_parts(db, airport: str, procedure: str, transition: str | None,
                 runway: str | None) -> list:
    """The database sequences that make the procedure, in flying order (module docstring).

    Raises
    ------
    UserError naming the procedure and the transitions it has, when a part is missing.
    """
    seqs = db.select(airport, procedure)
    kind = seqs[0].proc_type
    name = f"{airport} {procedure}"
    trans = sorted({s.transition for s in seqs})
    if kind == "F":
        final = [s for s in seqs if s.route_type != "A"]
        if not final:
            raise UserError(f"{name}: no final approach sequence in the database")
        parts = []
        if transition:
            t = [s for s in seqs if s.route_type == "A" and s.transition == transition]
            if not t:
                raise UserError(f"{name}: no approach transition {transition!r}; transitions: "
                                f"{', '.join(x for x in trans if x) or 'none'}")
            parts.append(t[0])
        parts.append(final[0])
        return parts
    rw = [s for s in seqs if _is_rw(s.transition)]
    common = [s for s in seqs if s.transition in ("", "ALL")]
    enroute = [s for s in seqs if s.transition not in ("", "ALL") and not _is_rw(s.transition)]
    rw_part = []
    if runway:
        rw_part = [s for s in rw if _runway_match(s.transition, runway)][:1]
        if not rw_part:
            raise UserError(f"{name}: no runway transition for {runway!r}; runway transitions: "
                            f"{', '.join(s.transition for s in rw) or 'none'}")
    en_part = []
    if transition:
        en_part = [s for s in enroute if s.transition == transition][:1]
        if not en_part:
            raise UserError(f"{name}: no transition {transition!r}; transitions: "
                            f"{', '.join(s.transition for s in enroute) or 'none'}")
    parts = (rw_part + common[:1] + en_part) if kind == "D" else (en_part + common[:1] + rw_part)
    if not parts:
        raise UserError(f"{name}: give --runway or --transition (runway transitions: "
                        f"{', '.join(s.transition for s in rw) or 'none'}; transitions: "
                        f"{', '.join(s.transition for s in enroute) or 'none'})")
    return parts


def merge_parts(parts: list, missed: bool = False):
    """One :class:`~fms_testbed.procedures.database.Sequence` from the parts; the approach is cut
    at its missed-approach point unless ``missed`` (the missed-approach legs are flown)."""
    legs = list(parts[0].legs)
    for p in parts[1:]:
        nxt = list(p.legs)
        if nxt and LEG_TYPES[nxt[0].path_term].initial and legs and legs[-1].fix is not None \
                and nxt[0].fix is not None and nxt[0].fix.ident == legs[-1].fix.ident:
            nxt = nxt[1:]
        elif nxt and LEG_TYPES[nxt[0].path_term].initial and legs and legs[-1].fix is not None \
                and LEG_TYPES[legs[-1].path_term].hold:
            # a transition ending in a hold (HF course reversal) at a fix the next part
            # reaches later (its IF lies outbound of it): join the next part at that fix
            # instead of flying back out to its IF
            at = legs[-1].fix.ident
            j = next((k for k, lg in enumerate(nxt) if k > 0 and lg.fix is not None
                      and lg.fix.ident == at), None)
            if j is not None:
                nxt = nxt[j + 1:]
        legs += nxt
    if parts[0].proc_type == "F" and not missed:
        cut = next((i for i, lg in enumerate(legs) if lg.missed_approach_start), len(legs))
        legs = legs[:cut]
    trans = "+".join(p.transition for p in parts if p.transition)
    return replace(parts[-1], transition=trans, legs=tuple(legs),
                   defects=tuple(d for p in parts for d in p.defects),
                   lines=tuple(ln for p in parts for ln in p.lines))




def plan_climb_rate_mps(cfg) -> float:
    """Planned climb rate, m/s: PLAN_CLIMB_FRACTION × ``limits.climb_rate_max_mps``."""
    return PLAN_CLIMB_FRACTION * cfg.limits.climb_rate_max_mps


@dataclass(frozen=True)
class FlyablePath:
    """A built procedure and what guidance needs besides it.

    path: the built and checked :class:`ProcedurePath` (profile attached); seq: the merged
    sequence it came from; leg_offset: index of its first leg in the whole procedure (non-zero
    after an in-flight rebuild); rnp_m: RNP per leg, m; degraded: what is in doubt in a
    degraded procedure built with ``allow_degraded`` (one 'file:line: field: reason' per
    defect of its records; empty for a sound procedure).
    """

    path: object
    seq: object
    leg_offset: int
    rnp_m: tuple[float, ...]
    degraded: tuple[str, ...] = ()
    params: object = None
    """The :class:`~fms_testbed.legs.model.BuildParams` it was built with (the planned wind):
    an in-flight rebuild uses the same."""


def _perf_params(cfg, spec: ProcedureSpec, wind=None, isa_dev_c: float = 0.0):
    """Performance and build settings for aircraft ``cfg``; ``wind`` (speed m/s, from deg
    true; or a :class:`~fms_testbed.core.wind.WindProfile` over altitude): the wind the path
    is planned for; ``isa_dev_c``: the planned ISA deviation, K."""
    from fms_testbed.core.wind import WindProfile
    from fms_testbed.legs.model import BuildParams, Performance

    perf = Performance.from_aircraft(cfg)
    grad = spec.climb_gradient or plan_climb_rate_mps(cfg) / perf.tas_plan_mps
    perf = replace(perf, climb_gradient_max=min(grad, perf.climb_gradient_max))
    prof = wind if isinstance(wind, WindProfile) else None
    if prof is not None:   # the constant fields: the wind at the lowest layer (per leg: its own)
        wind = prof.at(prof.alt_m[0])
        prof = prof if prof.layered else None
    w_mps, w_from = wind if wind is not None else (0.0, 0.0)
    params = BuildParams(manual_leg_m=spec.manual_leg_nm * NM_M,
                         bank_limit_deg=min(25.0, cfg.limits.bank_max_deg),
                         wind_speed_mps=float(w_mps), wind_from_deg=float(w_from),
                         wind_profile=prof, isa_dev_c=float(isa_dev_c),
                         climb_top_m=min(spec.climb_top_ft * FT_M, perf.alt_plan_max_m))
    return perf, params


def _rnp(seq, spec: ProcedureSpec, offset: int = 0) -> tuple[float, ...]:
    default = 0.3 if seq.proc_type == "F" else 1.0
    out = []
    for lg in seq.legs[offset:]:
        v = lg.rnp_nm if lg.rnp_nm else (spec.rnp_nm or default)
        out.append(v * NM_M)
    return tuple(out)


def _finish(path, seq, spec, cfg, perf, params, offset: int,
            in_missed: bool = False) -> FlyablePath:
    from fms_testbed.path.monitor import check_path
    from fms_testbed.path.profile import plan_profile

    checked = check_path(path, perf, params)
    if checked.legs:
        grad = perf.climb_gradient_at(perf.tas_plan_mps)
        # a missed approach climbs to its own coded altitudes (the highest of them), not to
        # the SID climb top
        missed = in_missed or any(r.missed_approach_start for r in seq.legs)
        top = None if checked.proc_type == "F" and missed else min(spec.climb_top_ft * FT_M,
                                                                   perf.alt_plan_max_m)
        prof = plan_profile(checked, grad, checked.legs[0].start.alt_m,
                            params.descent_angle_deg, climb_top_m=top,
                            descent_gradient_max=perf.descent_rate_max_mps / perf.tas_plan_mps,
                            descent_rate_mps=PLAN_CLIMB_FRACTION * perf.descent_rate_max_mps,
                            wind=(params.wind_speed_mps, params.wind_from_deg),
                            start_in_climb=in_missed, cas_plan_mps=cfg.limits.climb_cas_mps,
                            isa_dev_c=params.isa_dev_c, alt_max_m=perf.alt_plan_max_m)
        if checked.proc_type == "F" and cfg.approach is not None:
            prof = replace(prof, speed=approach_speed_profile(checked, prof, cfg))
        checked = replace(checked, profile=prof)
    return FlyablePath(checked, seq, offset, _rnp(seq, spec, 0))


def approach_clean_cas_mps(cfg) -> float:
    """CAS an approach is planned at before it slows (clean), m/s: the builder's approach
    speed (:func:`fms_testbed.legs.model.approach_cas_caps`), never above the aircraft's
    planned terminal-area speed."""
    from fms_testbed.legs.model import APPROACH_CAS_MPS

    return min(max(APPROACH_CAS_MPS, 1.15 * cfg.limits.cas_min_mps), cfg.limits.climb_cas_mps)


def approach_speed_profile(path, prof, cfg):
    """The planned speeds of an approach for aircraft ``cfg`` (its ``approach`` settings:
    Vapp at the reference mass, the planned deceleration), on the nodes of ``prof``
    (:func:`fms_testbed.path.speed_profile.plan_speed_profile`)."""
    from fms_testbed.path.speed_profile import plan_speed_profile

    ap = cfg.approach
    return plan_speed_profile(path, prof.along_m, prof.alt_m, approach_clean_cas_mps(cfg),
                              ap.vapp_cas_mps_at(None), ap.decel_mps2)


def build_procedure(db, spec: ProcedureSpec, cfg, wind=None,
                    isa_dev_c: float = 0.0) -> FlyablePath:
    """Select, merge, build and check the procedure a spec names, for aircraft ``cfg``, the
    planned ``wind`` (speed m/s, from deg true, or a
    :class:`~fms_testbed.core.wind.WindProfile`; None: calm) and ISA deviation (K).

    Raises
    ------
    UserError when the procedure cannot be found, is impossible to build (with the monitor's
    reason), or is degraded (a rejected, duplicated or misplaced record of its own; one line
    naming the record: file, line, field, reason) and ``spec.allow_degraded`` is not set. With
    it, the built path lists the defects in ``FlyablePath.degraded``.
    """
    from fms_testbed.path.segmentation import build_sequence
    from fms_testbed.procedures.integrity import refusal

    parts = select_parts(db, spec.airport, spec.procedure, spec.transition, spec.runway)
    if spec.missed and parts[0].proc_type != "F":
        raise UserError(f"{spec.airport} {spec.procedure}: missed: only an approach has a "
                        f"missed approach")
    seq = merge_parts(parts, missed=spec.missed)
    if seq.degraded and not spec.allow_degraded:
        raise UserError(refusal(seq.name, seq.defects))
    if not seq.legs:
        raise UserError(f"{seq.name}: no leg left to fly (every record rejected)")
    perf, params = _perf_params(cfg, spec, wind, isa_dev_c)
    path = build_sequence(db, seq, perf, params)
    start_alt = spec.start_alt_ft * FT_M if spec.start_alt_ft is not None else None
    if start_alt is None and seq.proc_type == "D" and path.start_kind != "runway" and path.legs:
        # a SID that starts at a fix (the runway part is vectors): arrive there high enough
        # for its climb constraints at the planned gradient (the monitor assumes the same)
        from fms_testbed.path.profile import sid_join_required_alt_m
        need = sid_join_required_alt_m(path, perf.climb_gradient_at(perf.tas_plan_mps))
        if need is not None and need > path.legs[0].start.alt_m:
            start_alt = need
    if start_alt is not None and path.legs:
        from fms_testbed.legs.model import FlightState
        st = path.legs[0].start
        start = FlightState(st.lat_deg, st.lon_deg, st.track_deg, start_alt,
                            st.flyby, st.fix_ident)
        path = replace(build_sequence(db, seq, perf, params, start=start),
                       start_kind=path.start_kind)
    fp = _finish(path, seq, spec, cfg, perf, params, 0)
    if fp.path.status == "impossible" or not fp.path.segments:
        why = "; ".join(f.message for f in fp.path.findings if f.category == "impossible")
        raise UserError(f"{seq.name}: the monitor finds the procedure impossible to fly: "
                        f"{why or 'no path segments'}")
    return replace(fp, degraded=tuple(str(d) for d in seq.defects), params=params)


def rebuild_from(db, whole: FlyablePath, spec: ProcedureSpec, cfg, next_leg: int,
                 lat_deg: float, lon_deg: float, track_deg: float, alt_m: float,
                 params=None, prev_fix=None) -> FlyablePath | None:
    """Build legs ``next_leg..`` of the procedure from the aircraft's actual state.

    Used when a conditional leg (altitude, DME, radial) ends in flight somewhere other than
    planned, and when the measured conditions differ from the planned ones (``params``: the
    build settings for the measured wind and temperature; default the whole path's;
    ``prev_fix``: the fix leg ``next_leg`` starts from, for a leg rebuilt mid-way). Returns
    None when nothing is left or the rest cannot be built.
    """
    from fms_testbed.legs.model import FlightState
    from fms_testbed.path.segmentation import build_sequence

    params_in = params
    legs = whole.seq.legs[next_leg:]
    if not legs:
        return None
    seq = replace(whole.seq, legs=legs)
    perf, params = _perf_params(cfg, spec)
    if whole.params is not None:
        params = whole.params
    if params_in is not None:
        params = params_in
    start = FlightState(lat_deg, lon_deg, track_deg, alt_m)
    path = build_sequence(db, seq, perf, params, start=start, prev_fix=prev_fix)
    if not path.segments or path.status == "impossible":
        return None
    # the rest of a missed approach climbs from its start (its first leg is not coded as the
    # missed-approach start)
    in_missed = any(r.missed_approach_start for r in whole.seq.legs[:next_leg])
    fp = _finish(path, seq, spec, cfg, perf, params, next_leg, in_missed)
    return replace(fp, rnp_m=whole.rnp_m[next_leg:], degraded=whole.degraded, params=params)
