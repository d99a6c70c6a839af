"""(bench/conditions_trim.py) Straight-and-level 737 at 250 kt CAS, 3000 m, ISA-20/0/+20: trimmed and flown TAS vs planned."""
from fms_testbed.config.scenario import parse_scenario
from fms_testbed.loop.flight import Flight
from fms_testbed.core.atmosphere import cas_to_tas, pressure_altitude_m
from fms_testbed.core.units import KT_MPS
for dev in (-20, 0, 20):
    scn = parse_scenario({"name": f"isa{dev}", "aircraft": "737", "duration_s": 60, "hold": True,
                          "initial": {"alt_m": 3000, "cas_kt": 250, "heading_deg": 90},
                          "atmosphere": {"isa_dev_c": dev}})
    f = Flight(scn, progress=False)
    df, summ = f.run()
    last = df.iloc[-1]
    want = float(cas_to_tas(250 * KT_MPS, 3000, dev))
    print(f"ISA{dev:+d}: JSBSim T {f.aircraft['atmosphere/T-R']/1.8:.2f} K, trim TAS {summ['trim']['tas_mps']/KT_MPS:.2f} kt, "
          f"planned TAS {want/KT_MPS:.2f} kt, flown TAS {last.tas_mps/KT_MPS:.2f} kt, flown CAS {last.cas_mps/KT_MPS:.2f} kt, "
          f"alpha {summ['trim']['alpha_deg']:.2f}, thr {summ['trim']['throttle']:.3f}, p-alt {pressure_altitude_m(3000, dev):.0f} m "
          f"JSBSim p-alt {f.aircraft['atmosphere/pressure-altitude']*0.3048:.0f} m, status {summ['status']}")
