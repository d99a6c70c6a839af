"""The results of one flight: the timeseries, a summary that serialises to ``summary.json``, and
what is needed to draw it (the built procedure, the paths rebuilt in flight).

Like python-control's ``TimeResponseData``: :meth:`Results.to_pandas` gives the data,
:meth:`Results.plot` returns figures (it draws, it does not compute), :meth:`Results.save`
writes the outputs of a run into a folder.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from fms_testbed.config.scenario import Scenario
from fms_testbed.core.errors import UserError
from fms_testbed.core.jsonio import dumps
from fms_testbed.loop.procedure import PreparedProcedure
from fms_testbed.run.outputs import OutputFolder, file_sha256
from fms_testbed.run.summary import Summary
from fms_testbed.viz.attitude_reference import plot_attitude_reference_run
from fms_testbed.viz.figure import save as save_figure
from fms_testbed.viz.geojson import write_track_geojson
from fms_testbed.viz.kml import write_track_kml
from fms_testbed.viz.procedure import plot_procedure
from fms_testbed.viz.run import plot_run


def write_sensors(sensors: dict, folder: Path) -> None:
    """Write recorded sensors as ``imu.parquet``, ``gnss.parquet``, ``truth.parquet`` and
    ``init.json`` (the ``nav-replay`` inputs) into ``folder``.

    Parameters
    ----------
    sensors : :meth:`fms_testbed.navigation.recording.SensorRecorder.tables`
    folder : the target folder (created)
    """
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("imu", "gnss", "truth"):
        sensors[name].to_parquet(folder / f"{name}.parquet", index=False)
    (folder / "init.json").write_text(dumps(sensors["init"]))


@dataclass
class Results:
    """One flown scenario.

    Attributes
    ----------
    df : timeseries, one row per logged step (:data:`fms_testbed.core.timeseries.COLUMNS`, then
        navigation-error and guidance columns)
    summary : :class:`Summary`
    scenario : the validated scenario that was flown
    procedure : the built procedure (procedure flights), else None
    flown_paths : paths rebuilt in flight (conditional legs), drawn on the track plot
    out_dir : where :meth:`save` last wrote the outputs (None: not written)
    """

    df: pd.DataFrame
    summary: Summary
    scenario: Scenario
    procedure: PreparedProcedure | None = None
    flown_paths: list = field(default_factory=list)
    out_dir: Path | None = None
    sensors: dict | None = None
    """A flight's recorded sensors (``navigation.record_sensors``: ``imu``, ``gnss``, ``truth``
    tables and the ``init`` mapping, :mod:`fms_testbed.navigation.recording`), written to
    ``sensors/`` in the replay's format."""

    def to_pandas(self) -> pd.DataFrame:
        """The timeseries as a DataFrame."""
        return self.df

    def plot(self) -> dict[str, Any]:
        """The standard figures of the flight, by file stem (``ground_track``, ``time_histories``
        and, for a procedure flight, ``procedure_track``, ``procedure_vertical``,
        ``procedure_errors``; ``attitude_reference`` in the flight-test attitude-reference
        mode); matplotlib :class:`~matplotlib.figure.Figure` objects."""
        figs = dict(plot_run(self.df, self.summary))
        figs.update(plot_attitude_reference_run(self.df, self.summary))
        if self.procedure is not None:
            figs.update(plot_procedure(self.df, self.summary, self.procedure.path,
                                       self.flown_paths))
        return figs

    def inputs(self) -> dict[str, dict]:
        """The files this flight was built from, with their SHA-256 (for ``run.json``)."""
        files = {"scenario": self.scenario.source_file, "aircraft": self.summary.aircraft_file}
        if self.procedure is not None and self.procedure.db is not None:
            files["procedure_db"] = self.procedure.db.path
        return {k: {"path": str(v), "sha256": file_sha256(v)} for k, v in files.items()
                if v and not str(v).startswith("<")}

    def _input_paths(self) -> list[str]:
        return [v["path"] for v in self.inputs().values()]

    def save(self, out_dir: str | Path, csv: bool = False, plots: bool = True,
             overwrite: bool = False, command: list[str] | None = None,
             kind: str | None = None) -> Path:
        """Write ``timeseries.parquet``, ``summary.json``, the PNG plots (and ``timeseries.csv``)
        and the tracks for Google Earth/QGIS (``track.geojson``, ``track.kml``: the designed path
        of a procedure flight and the flown 3-D track) into ``out_dir``, atomically
        (:class:`~fms_testbed.run.outputs.OutputFolder`: a previous run there is replaced as a
        whole; ``run.json`` is written last); return the folder.

        Parameters
        ----------
        out_dir : target folder
        csv : also write ``timeseries.csv``;  plots : write the PNG figures
        overwrite : replace a folder that holds something other than a testbed run
        command : the command line to record in ``run.json`` (default ``sys.argv``)
        kind : the kind of run recorded in ``run.json`` (default: the command's word,
            :func:`~fms_testbed.run.outputs.command_kind`); a previous run of another kind in
            ``out_dir`` is replaced only with ``overwrite``
        """
        folder = OutputFolder(out_dir, overwrite, kind, self._input_paths())
        try:
            with folder as tmp:
                self.df.to_parquet(tmp / "timeseries.parquet", index=False)
                if csv:
                    self.df.to_csv(tmp / "timeseries.csv", index=False, float_format="%.7g")
                names = tracks = None
                if plots:
                    names = [save_figure(fig, tmp / f"{stem}.png").name
                             for stem, fig in self.plot().items()]
                if not self.df.empty:   # tracks for Google Earth / QGIS (viz.geojson, viz.kml)
                    path = self.procedure.path.path if self.procedure is not None else None
                    tracks = [
                        w(tmp / name, self.df, self.summary, path, tuple(self.flown_paths)).name
                        for w, name in ((write_track_geojson, "track.geojson"),
                                        (write_track_kml, "track.kml"))]
                self.summary = self.summary.with_outputs(names, tracks)
                (tmp / "summary.json").write_text(self.summary.to_json())
                if self.sensors is not None:
                    write_sensors(self.sensors, tmp / "sensors")
                folder.set_run_info(**({"command": command} if command is not None else {}),
                                    scenario=self.summary.get("scenario"),
                                    seed=self.summary.get("seed"),
                                    status=self.summary.get("status"),
                                    reason=self.summary.get("reason"),
                                    inputs=self.inputs())
        except OSError as exc:
            raise UserError(f"--out {out_dir}: cannot write the outputs: "
                            f"{exc.strerror or exc}") from None
        self.out_dir = folder.out
        return folder.out


__all__ = ["Results", "Summary"]
