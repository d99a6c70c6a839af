"""mkdocs hook: the reference pages generated from the code at build time (never hand-copied).

* ``reference/cli.md`` from the argparse parser (:func:`fms_testbed.cli.build_parser`): every
  command and sub-command with its usage and a table of its arguments.
* ``reference/scenario.md`` from the pydantic schemas: the scenario file
  (:class:`fms_testbed.config.scenario.Scenario`), its ``procedure:`` block
  (:class:`fms_testbed.config.procedure.ProcedureSpec`), its ``navigation:`` block (the sources
  registered in :data:`fms_testbed.navigation.SOURCES`), the aircraft file
  (:class:`fms_testbed.config.aircraft.AircraftConfig`) and the IMU file
  (:class:`fms_testbed.sensors.sins.presets.ImuSpec`).
* ``reference/timeseries.md`` from :data:`fms_testbed.core.timeseries.COLUMNS`.

The pages are added to the build as generated files (``on_files``); nothing is written into
``docs/``. The functions are importable, so ``tests/test_docs.py`` checks their content too.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from griffe_rst import rst_to_markdown  # noqa: E402  (sibling hook module)

#: generated page (path under docs/) → function returning its Markdown
PAGES: dict[str, str] = {
    "reference/cli.md": "cli_markdown",
    "reference/scenario.md": "scenario_markdown",
    "reference/timeseries.md": "timeseries_markdown",
}

_GENERATED_NOTE = ("*Generated at build time by `docs/hooks/reference.py` from {src}; edit the "
                   "code, not this page.*\n")


def _cell(text: Any) -> str:
    """A Markdown table cell: one line, pipes escaped."""
    return " ".join(str(text).split()).replace("|", "\\|")


# ---------------------------------------------------------------- CLI (argparse)

def _subcommands(parser: argparse.ArgumentParser):
    for action in parser._actions:  # argparse keeps sub-parsers only here
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, sub, helps.get(name) or ""


def _argument_rows(parser: argparse.ArgumentParser) -> list[str]:
    fmt = parser._get_formatter()
    rows = []
    for a in parser._actions:
        if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        if a.help == argparse.SUPPRESS:
            continue
        name = ", ".join(f"`{s}`" for s in a.option_strings) or f"`{a.metavar or a.dest}`"
        if a.required and a.option_strings:
            name += " (required)"
        if a.choices is not None:
            value = " \\| ".join(f"`{c}`" for c in a.choices)
        elif a.nargs == 0:
            value = ""
        else:
            value = f"`{a.metavar or a.dest.upper()}`"
            if a.nargs in ("*", "+"):
                value += " …"
        default = a.default
        show = (default not in (None, False, argparse.SUPPRESS, [])
                and not (a.nargs == 0 and default is False))
        help_text = fmt._expand_help(a) if a.help else ""
        rows.append(f"| {name} | {value} | {f'`{default}`' if show else ''} | {_cell(help_text)} |")
    return rows


def _command_section(path: str, parser: argparse.ArgumentParser, summary: str, level: int,
                     out: list[str]) -> None:
    out.append(f"{'#' * level} `{path}`\n")
    text = parser.description or summary
    if text:
        out.append(rst_to_markdown(text).strip() + "\n")
    os.environ.setdefault("COLUMNS", "100")
    out.append("```text\n" + parser.format_usage().strip() + "\n```\n")
    rows = _argument_rows(parser)
    if rows:
        out.append("| argument | value | default | meaning |\n|---|---|---|---|")
        out.extend(rows)
        out.append("")
    if parser.epilog:
        out.append(parser.epilog.strip() + "\n")
    for name, sub, help_text in _subcommands(parser):
        _command_section(f"{path} {name}", sub, help_text, min(level + 1, 4), out)


def cli_markdown() -> str:
    """The CLI reference: every command of ``fms-testbed`` with its usage and arguments."""
    from fms_testbed.cli import build_parser

    parser = build_parser()
    out = ["# Command-line reference\n",
           _GENERATED_NOTE.format(src="`fms_testbed.cli.build_parser()`"),
           "Exit codes: 0 success, 1 the run or check did not meet its goal (diverged, "
           "incomplete, a failed goal), 2 a user error (one line on stderr naming the file "
           "and field or option).\n",
           "| command | what it does |\n|---|---|"]
    for name, _, help_text in _subcommands(parser):
        out.append(f"| [`{name}`](#fms-testbed-{name}) | {_cell(help_text)} |")
    out.append("")
    out.append("## Global options\n")
    out.append("```text\n" + parser.format_usage().strip() + "\n```\n")
    out.append("| argument | value | default | meaning |\n|---|---|---|---|")
    out.extend(_argument_rows(parser))
    out.append("")
    for name, sub, help_text in _subcommands(parser):
        _command_section(f"fms-testbed {name}", sub, help_text, 2, out)
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- schemas (pydantic)

def _type_of(prop: dict, defs: dict) -> str:
    if "$ref" in prop:
        name = prop["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{name.lower()})"
    if "const" in prop:
        return f"`{prop['const']!r}`"
    if "enum" in prop:
        return " \\| ".join(f"`{v}`" for v in prop["enum"])
    for key in ("anyOf", "oneOf"):
        if key in prop:
            parts = [_type_of(p, defs) for p in prop[key] if p.get("type") != "null"]
            s = " \\| ".join(parts)
            return s + (" or null" if any(p.get("type") == "null" for p in prop[key]) else "")
    t = prop.get("type", "any")
    if t == "array":
        return f"list of {_type_of(prop.get('items', {}), defs)}"
    if t == "object" and "additionalProperties" in prop and isinstance(
            prop["additionalProperties"], dict):
        return "mapping"
    return {"number": "number", "integer": "integer", "string": "string", "boolean": "boolean",
            "object": "mapping"}.get(t, str(t))


def _range_of(prop: dict) -> str:
    for key in ("anyOf", "oneOf"):
        if key in prop:
            return "; ".join(r for r in (_range_of(p) for p in prop[key]) if r)
    bits = []
    lo = ("≥", prop["minimum"]) if "minimum" in prop else (
        (">", prop["exclusiveMinimum"]) if "exclusiveMinimum" in prop else None)
    hi = ("≤", prop["maximum"]) if "maximum" in prop else (
        ("<", prop["exclusiveMaximum"]) if "exclusiveMaximum" in prop else None)
    if lo:
        bits.append(f"{lo[0]} {lo[1]:g}")
    if hi:
        bits.append(f"{hi[0]} {hi[1]:g}")
    if "minItems" in prop:
        bits.append(f"at least {prop['minItems']} item(s)")
    if "minLength" in prop or "maxLength" in prop:
        bits.append(f"{prop.get('minLength', 0)}-{prop.get('maxLength', '…')} characters")
    if "pattern" in prop:
        bits.append(f"matches `{prop['pattern']}`")
    return ", ".join(bits)


def _default_of(field) -> str:
    from pydantic_core import PydanticUndefined

    if field.is_required():
        return "**required**"
    if field.default_factory is not None:
        value = field.default_factory()
    elif field.default is PydanticUndefined:
        return ""
    else:
        value = field.default
    if value is None:
        return ""
    if hasattr(value, "model_dump"):
        return "see its table"
    return f"`{value!r}`" if isinstance(value, str) else f"`{value}`"


def _models_in(model) -> dict[str, type]:
    """Every pydantic model reachable from ``model``'s fields, by class name."""
    import typing

    from pydantic import BaseModel

    found: dict[str, type] = {}

    def walk(tp):
        if isinstance(tp, type) and issubclass(tp, BaseModel):
            if tp.__name__ not in found:
                found[tp.__name__] = tp
                for f in tp.model_fields.values():
                    walk(f.annotation)
            return
        for arg in typing.get_args(tp):
            walk(arg)

    walk(model)
    return found


def _model_table(title: str, model, schema: dict, defs: dict, level: int,
                 skip=("source_file",)) -> list:
    out = [f"{'#' * level} {title}\n"]
    doc = inspect.getdoc(model)
    if doc and doc != inspect.getdoc(model.__mro__[1]):
        out.append(rst_to_markdown(doc) + "\n")
    props = schema.get("properties", {})
    out.append("| key | type | default | range | meaning |\n|---|---|---|---|---|")
    for key, field in model.model_fields.items():
        if key in skip:
            continue
        prop = props.get(field.alias or key, {})
        out.append(f"| `{key}` | {_type_of(prop, defs)} | {_default_of(field)} "
                   f"| {_cell(_range_of(prop))} | {_cell(field.description or '')} |")
    out.append("")
    return out


def _schema_section(title: str, model, intro: str = "", level: int = 2) -> list[str]:
    schema = model.model_json_schema()
    defs = schema.get("$defs", {})
    models = _models_in(model)
    out = [f"{'#' * level} {title}\n"]
    if intro:
        out.append(intro + "\n")
    out += _model_table(f"`{model.__name__}`", model, schema, defs, level + 1)
    for name, sub in defs.items():
        if name in models:
            out += _model_table(name, models[name], sub, defs, level + 1)
    return out


def _docstring_block(obj) -> str:
    return rst_to_markdown(inspect.getdoc(obj) or "")


def scenario_markdown() -> str:
    """The file-format reference: scenario, procedure and navigation blocks, aircraft, IMU."""
    import fms_testbed.config.scenario as scenario_mod
    from fms_testbed.config.aircraft import AircraftConfig
    from fms_testbed.config.procedure import ProcedureSpec
    from fms_testbed.config.scenario import Scenario
    from fms_testbed.navigation import SOURCES
    from fms_testbed.sensors.sins.presets import ImuSpec

    out = ["# Scenario, aircraft and IMU files\n",
           _GENERATED_NOTE.format(src="the pydantic schemas in `fms_testbed.config` and the "
                                  "navigation sources' own documentation"),
           "Every file is validated on load: an unknown key, a wrong type, an out-of-range value "
           "or conflicting keys stop with one line naming the file and the field "
           "(`FILE: field 'events.0.bank_deg': …`) and exit code 2.\n",
           "## Scenario file\n", _docstring_block(scenario_mod) + "\n"]
    out += _schema_section("Scenario keys", Scenario, level=2)[1:]
    out += _schema_section("`procedure:` block", ProcedureSpec,
                           "A scenario with this block is a procedure flight "
                           "(see [Flying procedures](../flying.md)). `initial` then defaults to "
                           "the start of the built path, `duration_s` to the planned flight time "
                           "with a margin.")
    out.append("## `navigation:` block\n")
    out.append("`source` names a registered navigation source "
               "(`fms_testbed.navigation.SOURCES`); the other keys belong to that source. "
               "Without the block the navigation solution is the truth.\n")
    for name, cls in SOURCES.items():
        mod = importlib.import_module(cls.__module__)
        out.append(f"### `source: {name}` — `{cls.__module__}.{cls.__name__}`\n")
        out.append(_docstring_block(mod) + "\n")
    out += _schema_section("Aircraft file (`fms_testbed/data/aircraft/NAME.yaml`)",
                           AircraftConfig, _docstring_block(
                               importlib.import_module(AircraftConfig.__module__)))
    out += _schema_section("IMU file (`fms_testbed/data/imu/NAME.yaml`)", ImuSpec,
                           "One YAML file per IMU preset; values are 1σ per axis, the unit is in "
                           "each key. A scenario's `navigation.imu` names a preset, a file, or "
                           "gives the mapping inline.")
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- timeseries

def timeseries_markdown() -> str:
    """The timeseries column contract as a table."""
    from fms_testbed.core import timeseries

    return ("# Timeseries columns\n\n"
            + _GENERATED_NOTE.format(src="`fms_testbed.core.timeseries.COLUMNS`") + "\n"
            + "One row per logged step (`log_rate_hz`), in `timeseries.parquet` and `Results.df`, "
              "in this order. Columns after these are added by the navigation source (its error "
              "components) and, in a procedure flight, by the guidance (see "
              "[Flying procedures](../flying.md#outputs)).\n\n"
            + timeseries.column_doc_markdown() + "\n")


# ---------------------------------------------------------------- tables inside hand-written pages

def _first_line(obj) -> str:
    doc = inspect.getdoc(obj) or ""
    return rst_to_markdown(doc.split("\n\n", 1)[0].replace("\n", " "))


def leg_types_table() -> str:
    """The 23 path terminators from :data:`fms_testbed.legs.base.LEG_TYPES` with their
    properties (class attributes)."""
    importlib.import_module("fms_testbed.legs.types")   # defines every leg family
    from fms_testbed.legs.base import LEG_TYPES

    props = ("heading_leg", "conditional", "altitude_terminated", "ends_at_fix", "direct_to",
             "hold", "course_reversal")
    rows = ["| code | class | what it is | properties | arc | PDE reference |",
            "|---|---|---|---|---|---|"]
    for code in sorted(LEG_TYPES):
        cls = LEG_TYPES[code]
        flags = ", ".join(f"`{p}`" for p in props if getattr(cls, p, False))
        rows.append(f"| `{code}` | `{cls.__name__}` | {_cell(_first_line(cls))} | {flags} | "
                    f"{getattr(cls, 'arc_centre', None) or ''} | "
                    f"{getattr(cls, 'pde_reference', None) or '— (no coded path)'} |")
    return "\n".join(rows)


def aircraft_table() -> str:
    """The shipped aircraft files: model, category, design point, envelope points."""
    from fms_testbed.config.aircraft import list_aircraft, load_aircraft

    rows = ["| name | JSBSim model | category | design point (alt m / TAS m/s) | envelope points "
            "(alt m / TAS m/s) | coupled-law gains T_V s, ξ_V, T_H s, ξ_H |",
            "|---|---|---|---|---|---|"]
    for name in list_aircraft():
        c = load_aircraft(name)
        d = c.default_condition
        env = ", ".join(f"{p.alt_m:.0f} / {p.tas_mps:.0f}" for p in c.envelope)
        law = c.coupled_law
        gains = (f"{law.T_V_s:g}, {law.xi_V:g}, {law.T_H_s:g}, {law.xi_H:g}" if law else "—")
        rows.append(f"| `{name}` | `{c.jsbsim_model}` | {c.category} | {d.alt_m:.0f} / "
                    f"{d.tas_mps:.1f} | {env} | {gains} |")
    return "\n".join(rows)


def imu_presets_table() -> str:
    """The shipped IMU presets (``fms_testbed/data/imu/*.yaml``) in datasheet units."""
    import yaml

    from fms_testbed.data import imu_dir
    from fms_testbed.sensors.sins.presets import ImuSpec

    def bias(turn_on, inst, tau, unit):
        bits = []
        if turn_on:
            bits.append(f"{turn_on:g} {unit} turn-on")
        if inst:
            bits.append(f"{inst:g} {unit}" + (f" (GM τ {tau:g} s)" if tau else " constant"))
        return " + ".join(bits) or "0"

    rows = ["| preset | grade | gyro bias | ARW °/√h | accel bias | VRW m/s/√h | scale factor "
            "gyro / accel, ppm | misalignment gyro / accel, mrad |", "|---|---|---|---|---|---|---|---|"]
    sources = []
    for path in sorted(imu_dir().glob("*.yaml"), key=lambda p: p.stem.lower()):
        spec = ImuSpec.model_validate(yaml.safe_load(path.read_text()))
        g, a = spec.gyro, spec.accelerometer
        rows.append(
            f"| `{path.stem}` | {spec.grade} | "
            f"{bias(g.bias_turn_on_deg_per_h, g.bias_instability_deg_per_h, g.bias_correlation_time_s, '°/h')}"
            f" | {g.arw_deg_per_sqrt_h:g} | "
            f"{bias(a.bias_turn_on_ug, a.bias_instability_ug, a.bias_correlation_time_s, 'µg')} | "
            f"{a.vrw_mps_per_sqrt_h:g} | {g.scale_factor_ppm:g} / {a.scale_factor_ppm:g} | "
            f"{g.misalignment_mrad:g} / {a.misalignment_mrad:g} |")
        sources.append(f"- `{path.stem}`: {' '.join(spec.source.split())}")
    return "\n".join(rows) + "\n\nSources, as each file's `source:` states them:\n\n" + "\n".join(sources)


def registry_table(which: str) -> str:
    """Names and classes of a registry: ``navigation`` (SOURCES) or ``laws`` (VERTICAL_LAWS)."""
    if which == "navigation":
        from fms_testbed.navigation import SOURCES as reg
        key = "`navigation.source`"
    else:
        from fms_testbed.control import VERTICAL_LAWS as reg
        key = "`vertical_law`"
    rows = [f"| {key} | class | what it is |", "|---|---|---|"]
    for name, cls in reg.items():
        rows.append(f"| `{name}` | `{cls.__module__}.{cls.__name__}` | {_cell(_first_line(cls))} |")
    return "\n".join(rows)


def commands_table() -> str:
    """One line per CLI command and sub-command, linked to the CLI reference."""
    from fms_testbed.cli import build_parser

    rows = ["| command | what it does |", "|---|---|"]

    def walk(path, parser):
        for name, sub, help_text in _subcommands(parser):
            full = f"{path} {name}"
            slug = full.replace(" ", "-")
            rows.append(f"| [`{full}`](reference/cli.md#{slug}) | {_cell(help_text)} |")
            walk(full, sub)

    walk("fms-testbed", build_parser())
    return "\n".join(rows)


def rst_simple_table(text: str) -> str:
    """The first reStructuredText simple table (``===  ===`` rules) in ``text`` as Markdown."""
    lines = text.splitlines()
    rules = [i for i, ln in enumerate(lines) if ln.strip() and set(ln.strip()) <= {"=", " "}]
    if len(rules) < 3:
        raise ValueError("no simple table in the text")
    rule = lines[rules[0]]
    spans, i = [], 0
    while i < len(rule):
        if rule[i] == "=":
            j = i
            while j < len(rule) and rule[j] == "=":
                j += 1
            spans.append((i, j))
            i = j
        else:
            i += 1

    def cells(ln):
        return [ln[a:(spans[k + 1][0] if k + 1 < len(spans) else None)].strip()
                for k, (a, _) in enumerate(spans)]

    header = cells(lines[rules[0] + 1])
    rows: list[list[str]] = []
    for ln in lines[rules[1] + 1:rules[2]]:
        c = cells(ln)
        if c[0] or not rows:
            rows.append(c)
        else:  # continuation line
            rows[-1] = [f"{a} {b}".strip() for a, b in zip(rows[-1], c)]
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_cell(rst_to_markdown(x)) for x in r) + " |" for r in rows]
    return "\n".join(out)


def statuses_table() -> str:
    """The run statuses and exit codes, from :mod:`fms_testbed.evaluation.outcome`."""
    mod = importlib.import_module("fms_testbed.evaluation.outcome")
    return rst_simple_table(inspect.getdoc(mod))


#: ``<!-- generated: NAME -->`` in a page → the function that writes it
SNIPPETS = {
    "timeseries_columns": lambda: importlib.import_module(
        "fms_testbed.core.timeseries").column_doc_markdown(),
    "leg_types": leg_types_table,
    "aircraft": aircraft_table,
    "imu_presets": imu_presets_table,
    "navigation_sources": lambda: registry_table("navigation"),
    "vertical_laws": lambda: registry_table("laws"),
    "commands": commands_table,
    "statuses": statuses_table,
}

def modules_table(*layers: str) -> str:
    """Module → the first line of its docstring, for the public modules of ``layers``
    (read with griffe, nothing imported)."""
    import griffe

    rows = ["| module | concept |", "|---|---|"]
    for layer in layers:
        pkg = griffe.load(f"fms_testbed.{layer}", search_paths=[str(REPO)])
        for mod in layer_modules(layer):
            obj = pkg
            for part in mod.split(".")[2:]:
                obj = obj.modules[part]
            doc = obj.docstring.value if obj.docstring else ""
            first = rst_to_markdown(doc.split("\n\n", 1)[0].replace("\n", " "))
            rows.append(f"| [`{mod}`](api/{layer}.md#{mod}) | {_cell(first)} |")
    return "\n".join(rows)


_SNIPPET = __import__("re").compile(r"<!-- generated: ([a-z_]+)((?: [a-z_]+)*) -->")


def expand(markdown: str) -> str:
    """Replace every ``<!-- generated: NAME [ARG ...] -->`` marker by its table (unknown name:
    error). ``modules LAYER ...`` lists the modules of those layers."""
    def sub(m):
        name, args = m.group(1), m.group(2).split()
        if name == "modules":
            return modules_table(*args)
        if name not in SNIPPETS:
            raise KeyError(f"unknown generated table {name!r}; known: modules, "
                           f"{', '.join(SNIPPETS)}")
        return SNIPPETS[name]()

    return _SNIPPET.sub(sub, markdown)


def on_page_markdown(markdown, page, config, files):
    """Fill the generated tables of hand-written pages."""
    return expand(markdown)


# ---------------------------------------------------------------- API reference (mkdocstrings)

REPO = Path(__file__).resolve().parents[2]


def layers() -> list[str]:
    """The package's layers, top (cli) to bottom (core), from the import-linter contract."""
    import tomllib

    conf = tomllib.loads((REPO / "pyproject.toml").read_text())
    contract = next(c for c in conf["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    return [name.rsplit(".", 1)[-1] for name in contract["layers"]]


def layer_modules(layer: str) -> list[str]:
    """Public modules of one layer (files found on disk, nothing imported), package first."""
    root = REPO / "fms_testbed" / layer
    mods = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(REPO / "fms_testbed").with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts) or "__pycache__" in path.parts:
            continue
        # only regular packages (a folder without __init__.py is no importable package yet)
        folders = [path.parent, *path.parent.parents]
        folders = folders[:folders.index(REPO / "fms_testbed")]
        if not all((d / "__init__.py").exists() for d in folders):
            continue
        mods.append(".".join(["fms_testbed", *parts]))
    return sorted(mods, key=lambda m: (m.count("."), m))


def api_markdown(layer: str) -> str:
    """One API page: every public module of ``layer`` through mkdocstrings."""
    mods = layer_modules(layer)
    out = [f"# `fms_testbed.{layer}`\n",
           _GENERATED_NOTE.format(src="the modules of the layer and their numpydoc docstrings"),
           "\n".join(f"- [`{m}`](#{m})" for m in mods[1:]) + "\n"]
    for i, m in enumerate(mods):
        opts = ("    options:\n      show_root_heading: true\n      heading_level: 2\n"
                + ("      members: false\n" if i == 0 and len(mods) > 1 else ""))
        out.append(f"::: {m}\n{opts}")
    return "\n".join(out) + "\n"


def api_pages() -> dict[str, str]:
    """Generated API page path → layer, for every layer that has modules."""
    return {f"api/{layer}.md": layer for layer in reversed(layers()) if layer_modules(layer)}


# ---------------------------------------------------------------- mkdocs hook

def generate(name: str) -> str:
    """The Markdown of generated page ``name`` (a key of :data:`PAGES` or of :func:`api_pages`)."""
    if name in PAGES:
        return globals()[PAGES[name]]()
    return api_markdown(api_pages()[name])


def on_files(files, config):
    """Add the generated reference pages to the build."""
    from mkdocs.structure.files import File

    for src_uri in [*PAGES, *api_pages()]:
        files.append(File.generated(config, src_uri, content=generate(src_uri)))
    return files


def on_config(config):
    """Fill the nav's 'API reference' section with one page per layer, bottom (core) up."""
    for entry in config["nav"] or []:
        if isinstance(entry, dict) and "API reference" in entry:
            entry["API reference"] = [{f"fms_testbed.{layer}": src}
                                      for src, layer in api_pages().items()]
    return config
