"""MEMS gyro drift: error model, three-stage compensation, Allan identification, INS equivalent.

Seed 000 of the project: Vorobyov, Krayneva, Zvereva, Kondratyev, "Micromechanical gyroscope
drift compensation methods research" (MIEA), on a Sensonor STIM210. Its pipeline, one module
per concept:

* :mod:`.preset` — the preset file (``fms_testbed/data/mems/STIM210.yaml``, units in the keys,
  each value's public source named) and its SI model;
* :mod:`.temperature` — temperature profiles (``warmup``, ``ramp``, ``constant``, CSV) and the
  play-operator hysteresis;
* :mod:`.model` — the gyro output: zero signal vs temperature, hysteresis, run-to-run offset,
  flicker bias instability, rate random walk, angle random walk, quantisation;
* :mod:`.compensation` — the three stages (temperature calibration, run-to-run, slow drift);
* :mod:`.allan` — overlapping Allan deviation (allantools) and its ARW / bias-instability fit;
* :mod:`.static_test` — the static ``imu-test`` and its results object;
* :mod:`.reproduction` — the seed's figures over several switch-ons;
* :mod:`.equivalent` — the residual error as a SINS :class:`ImuModel` (``load_imu("STIM210+compensated")``).

Data contract: axes x, y, z of the gyro module; rates in rad/s inside (``*_rps``), °/s and °/h
only in preset keys, summaries and plots whose names say so (``*_deg_per_s``, ``*_deg_per_h``);
temperatures in °C (``*_degC``); times in s from switch-on (``t_s``). Arrays of a triad are
(n, 3). Every random draw comes from a ``numpy.random.Generator`` built from the caller's seed.
"""
