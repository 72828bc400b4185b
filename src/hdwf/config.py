"""Load and validate the study configuration against its JSON schema.

Snakemake's own ``validate`` reports jsonschema's raw message; we re-word it so the user
reads the file, the dotted key path, the value and what was expected.
"""

from __future__ import annotations

import functools
import json
import math
import re
from collections.abc import Iterator
from pathlib import Path

import jsonschema
import yaml

from hdwf.common.errors import ConfigError
from hdwf.validation.effects import registry

#: The schema of config.yaml, shipped inside the package so the CLI works from any folder.
SCHEMA_PATH = Path(__file__).with_name("config.schema.yaml")


@functools.lru_cache(maxsize=4)
def _schema(path: str) -> dict:
    """The schema file, read once per process (never modified: defaults are copied out of it)."""
    return yaml.safe_load(Path(path).read_text())


def fe_option_bounds(name: str, schema_path: str | Path = SCHEMA_PATH) -> tuple[float, float, bool]:
    """The schema's limits of the ``fe`` section's option ``name``: (low, high, low excluded).

    The CLI's mesh and load options take them from here, so a command line accepts what a
    config accepts and no more.
    """
    prop = _schema(str(schema_path))["properties"]["fe"]["properties"][name]
    low_open = "exclusiveMinimum" in prop
    return prop["exclusiveMinimum" if low_open else "minimum"], prop["maximum"], low_open


def _key_path(error: jsonschema.ValidationError) -> str:
    return ".".join(str(p) for p in error.absolute_path) or "(top level)"


def validate_config(config: dict, schema_path: str | Path = SCHEMA_PATH,
                    source: str | Path | list[str | Path] = "config.yaml") -> dict:
    """Validate ``config`` in place, filling schema defaults; raise ConfigError on the first problem.

    Every problem found is listed in the message, worst (shallowest) first.

    Parameters
    ----------
    config
        The merged configuration.
    schema_path
        The JSON schema (YAML).
    source
        The file the config was read from, or the files in the order they were merged (later
        ones override, as Snakemake's ``configfile:`` then ``--configfile``): a problem is then
        blamed on the last file that sets the offending key, or on ``--config`` if none does.
    """
    sources = [source] if isinstance(source, (str, Path)) else list(source)
    schema = _schema(str(schema_path))
    _null_clears_a_mapping(config, schema)
    try:
        _empty_overlay_mappings(sources, config, schema)
        _check_schema(config, schema_path, sources[-1])
        _check_relations(config, sources[-1])
    except ConfigError as exc:
        if len(sources) < 2 or exc.field is None:
            raise
        raise ConfigError(blame(sources, exc.field, exc.value), exc.problem, row=exc.row, field=exc.field,
                          value=exc.value) from None
    return config


def blame(sources: list[str | Path], field: str, value=None) -> str:
    """The last of ``sources`` (merged in order) whose YAML sets the dotted key ``field``.

    If that file sets it to another value than the offending ``value``, ``--config`` on the
    command line overrode it. A bad key name (an unknown effect, a campaign name with a space) is
    reported as the mapping's field with the key as its value, or as its own field: the file that
    holds that key set it. Mappings merge across the files, so a mapping without the key sends the
    search on to the files before; a list or a value replaces the earlier ones'.
    """
    for path in reversed(sources):
        try:
            node = yaml.safe_load(Path(path).read_text())
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            continue
        for key in field.split("."):
            if isinstance(node, dict) and key.isdigit() and key not in node and int(key) in node:
                key = int(key)   # YAML's `7:` is a number, the dotted field its text
            if isinstance(node, dict) and key in node:
                node = node[key]
            elif isinstance(node, list) and key.isdigit() and int(key) < len(node):
                node = node[int(key)]
            else:
                break
        else:
            if value is None or node == value or field.rsplit(".", 1)[-1] == str(value):
                return str(path)
            if isinstance(node, (dict, list)) and isinstance(value, (str, int, float)) and value in node:
                return str(path)
            if isinstance(node, dict):
                continue
            return "--config (command line)"
    return "--config (command line)"


PAPER_SETS = 27   # design points of the paper's Tables 4 and 5


def design_ids(config: dict, study: str, unit: str) -> list[str]:
    """The design ids of a study's drive, known from the config alone: the paper's sets
    (``paper-01`` …) or our Latin hypercube's (``hd42-lhs-01`` …, ``hdwf.stages.doe``)."""
    if config["studies"][study].get("designs", "paper") == "paper":
        return [f"paper-{i:02d}" for i in range(1, PAPER_SETS + 1)]
    return [f"{unit}-lhs-{i:02d}" for i in range(1, config["doe"]["n_designs"] + 1)]


def _not_a_number(value, path: str = "") -> str | None:
    """The key path of the first NaN in a config (YAML's .nan passes every bound of a schema)."""
    if isinstance(value, float) and math.isnan(value):
        return path or "(top level)"
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, sub in items:
        found = _not_a_number(sub, f"{path}.{key}" if path else str(key))
        if found:
            return found
    return None


def _clearable(schema: dict | None) -> bool:
    """Whether ``key: null`` clears this key (``_null_clears_a_mapping``): a mapping with a ``{}`` default."""
    return isinstance(schema, dict) and schema.get("type") == "object" and schema.get("default") == {}


def _schema_at(schema: dict, keys: list[str]) -> dict | None:
    """The schema of the value at ``keys`` (through ``properties`` and mapping ``additionalProperties``)."""
    for key in keys:
        extra = schema.get("additionalProperties")
        sub = schema.get("properties", {}).get(key, extra if isinstance(extra, dict) else None)
        if not isinstance(sub, dict):
            return None
        schema = sub
    return schema


def _null_clears_a_mapping(node: dict, schema: dict) -> None:
    """``key: null`` where the schema wants a mapping with a default reads as that default (``{}``).

    Overlays merge mapping into mapping, so an overlay's ``fe: {effects: {}}`` changes nothing;
    ``effects: null`` replaces the base's mapping, and this turns it into the empty one.
    """
    for key, value in node.items():
        sub = _schema_at(schema, [key])
        if sub is None:
            continue
        if value is None and _clearable(sub):
            node[key] = {}
        elif isinstance(value, dict):
            _null_clears_a_mapping(value, sub)


def _empty_overlay_mappings(sources: list[str | Path], config: dict, schema: dict) -> None:
    """Refuse an overlay's empty mapping over a non-empty one where null would clear it: it merges
    into nothing, so the run would keep what the user meant to clear (the studies' effects, say)
    and say nothing. Elsewhere (``doe: {}``, say) an empty mapping changes nothing and harms nothing."""
    for path in sources[1:]:
        try:
            overlay = yaml.safe_load(Path(path).read_text())
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            continue
        for field in _empty_mappings(overlay):
            merged = config
            for key in field.split("."):
                merged = merged.get(key) if isinstance(merged, dict) else None
            if isinstance(merged, dict) and merged and _clearable(_schema_at(schema, field.split("."))):
                raise ConfigError(path, "an empty mapping in an overlay merges into the base's and clears nothing "
                                        f"(it keeps {', '.join(map(str, merged))}): write null to clear it",
                                  field=field, value={})


def _empty_mappings(node, path: str = "") -> Iterator[str]:
    if not isinstance(node, dict):
        return
    for key, value in node.items():
        here = f"{path}.{key}" if path else str(key)
        if value == {}:
            yield here
        else:
            yield from _empty_mappings(value, here)


def _check_schema(config: dict, schema_path: str | Path, source) -> None:
    nan_at = _not_a_number(config)
    if nan_at:
        raise ConfigError(source, "not a number (NaN): give a value", field=nan_at, value=float("nan"))
    schema = _schema(str(schema_path))
    validator_cls = jsonschema.validators.validator_for(schema)
    # Fill defaults so downstream code never meets a missing optional key.
    def set_defaults(validator, properties, instance, schema_):
        if isinstance(instance, dict):
            for key, sub in properties.items():
                if isinstance(sub, dict) and "default" in sub:
                    instance.setdefault(key, json.loads(json.dumps(sub["default"])))
        yield from validator_cls.VALIDATORS["properties"](validator, properties, instance, schema_)

    extended = jsonschema.validators.extend(validator_cls, {"properties": set_defaults})
    errors = sorted(extended(schema).iter_errors(config), key=lambda e: (len(e.absolute_path), str(e.absolute_path)))
    if errors:
        first = errors[0]
        others = _and_the_others([f"{_key_path(e)}: {e.message}" for e in errors[1:]])
        value = first.instance if not isinstance(first.instance, (dict, list)) else None
        field = _key_path(first)
        unexpected = _unexpected_keys(first)
        if unexpected:   # name the key itself, so the file that holds it is the one blamed
            field = ".".join(p for p in (*map(str, first.absolute_path), unexpected[0]))
        raise ConfigError(source, f"{first.message}{others}", field=field, value=value)


def _unexpected_keys(error: jsonschema.ValidationError) -> list[str]:
    """The keys an ``additionalProperties: false`` error refuses (none for any other error)."""
    if error.validator != "additionalProperties" or not isinstance(error.instance, dict):
        return []
    known = set(error.schema.get("properties", {}))
    patterns = [re.compile(p) for p in error.schema.get("patternProperties", {})]
    return sorted(str(k) for k in error.instance
                  if k not in known and not any(p.search(str(k)) for p in patterns))


def _and_the_others(problems: list[str], shown: int = 10) -> str:
    """' (and N more problem(s): a; b; …)' after the first problem of a config, or '' if none."""
    if not problems:
        return ""
    more = "; …" if len(problems) > shown else ""
    return f" (and {len(problems)} more problem(s): " + "; ".join(problems[:shown]) + more + ")"


def _check_relations(config: dict, source) -> None:
    """Rules a JSON schema cannot express: every problem found, the first with the others listed."""
    problems = list(_relation_problems(config, source))
    if problems:
        first = problems[0]
        others = _and_the_others([f"{p.field}: {p.problem}" for p in problems[1:]])
        raise ConfigError(source, f"{first.problem}{others}", field=first.field, value=first.value)


def _relation_problems(config: dict, source) -> Iterator[ConfigError]:
    fe = config.get("fe")
    if fe is not None:
        refs = fe["convergence"]["refinements"]
        if fe["refinement"] not in refs:
            yield ConfigError(source, f"must contain fe.refinement ({fe['refinement']}), the default mesh, as one of "
                              "the three meshes", field="fe.convergence.refinements", value=refs)
        elif fe["refinement"] == min(refs):
            # The check compares the two finest meshes, so the study's own mesh must be one of them.
            yield ConfigError(source, "the default mesh must be one of the two finest of the three",
                              field="fe.refinement", value=fe["refinement"])
        yield from _effect_problems("fe", fe.get("effects", {}), source)
        fe_study_ok = {}
        for key in ("convergence", "picture"):
            study = fe.get(key, {}).get("study")
            fe_study_ok[key] = study in config["studies"] and config["studies"][study]["source"] == "fe"
            if study is not None and not fe_study_ok[key]:
                yield ConfigError(source, "must name an fe study", field=f"fe.{key}.study", value=study)
        picture = fe.get("picture", {})
        if "design" in picture and "study" in picture and fe_study_ok["picture"]:
            units = config["studies"][picture["study"]]["units"]
            missing = [u for u in units if picture["design"] not in design_ids(config, picture["study"], u)]
            if missing:
                yield ConfigError(source, f"no such design of study '{picture['study']}' for {', '.join(missing)} "
                                  f"(e.g. {design_ids(config, picture['study'], missing[0])[0]})",
                                  field="fe.picture.design", value=picture["design"])
    for name, study in config.get("studies", {}).items():
        if study["source"] == "paper" and study.get("designs", "paper") != "paper":
            yield ConfigError(source, "a paper study uses the paper's designs", field=f"studies.{name}.designs",
                              value=study["designs"])
    for name, camp in config.get("validation", {}).items():
        yield from _campaign_problems(name, camp, source)
    sob = config.get("sobol", {})
    n_start = sob.get("n_start")
    if n_start is not None and n_start & (n_start - 1):
        yield ConfigError(source, "must be a power of two (Sobol' sequences need it)", field="sobol.n_start",
                          value=n_start)
    if n_start is not None and not n_start <= sob["n_min"] <= sob["n_max"]:
        yield ConfigError(source, f"need n_start <= n_min <= n_max, got {n_start}, {sob['n_min']}, {sob['n_max']}",
                          field="sobol.n_min", value=sob["n_min"])


def _campaign_problems(name: str, camp: dict, source) -> Iterator[ConfigError]:
    """Effect names, parameters and values of a campaign against the effects registry."""
    known = registry()
    where = f"validation.{name}"
    yield from _effect_problems(where, camp.get("effects", {}), source)
    yield from _effect_problems(where, camp.get("hidden_effects", {}), source, key="hidden_effects")
    cands = camp.get("candidates", "all")
    if cands != "all":
        for c in cands:
            if c not in known:
                yield ConfigError(source, f"unknown effect; known: {', '.join(known)}", field=f"{where}.candidates",
                                  value=c)


def _effect_problems(where: str, effects: dict, source, key: str = "effects") -> Iterator[ConfigError]:
    """Effects ``{name: {parameter: value | calibrate}}`` at ``where.key`` against the registry."""
    known = registry()
    for eff, params in effects.items():
        if eff not in known:
            yield ConfigError(source, f"unknown effect; known: {', '.join(known)}", field=f"{where}.{key}",
                              value=eff)
            continue
        names = {p.name for p in known[eff].parameters}
        for pname, value in params.items():
            field = f"{where}.{key}.{eff}.{pname}"
            if pname not in names:
                yield ConfigError(source, f"unknown parameter of {eff}; it has {', '.join(sorted(names))}",
                                  field=field, value=pname)
            elif value != "calibrate":
                try:
                    known[eff].param(pname).check(value, field)
                except ValueError as exc:
                    yield ConfigError(source, str(exc).split(": ", 1)[-1], field=field, value=value)
        missing = names - set(params)
        if missing:
            yield ConfigError(source, f"give every parameter of {eff} (missing {', '.join(sorted(missing))})",
                              field=f"{where}.{key}.{eff}")


def _read_yaml(path: Path) -> dict:
    try:
        loaded = yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else "not a text file"
        raise ConfigError(path, f"cannot read the config: {reason}") from exc
    except yaml.YAMLError as exc:
        raise ConfigError(path, f"not valid YAML: {exc}") from exc
    if loaded is None:
        raise ConfigError(path, "the file is empty: a config needs keys at its top level (Snakemake refuses it too)")
    if not isinstance(loaded, dict):
        raise ConfigError(path, f"the top level must be keys and values (a mapping), not a {type(loaded).__name__}")
    return loaded


def _merge(base: dict, override: dict) -> dict:
    """``override`` merged into ``base`` key by key, nested mappings recursively (as Snakemake merges
    ``--configfile`` files over the Snakefile's ``configfile:``)."""
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            _merge(base[key], value)
        else:
            base[key] = value
    return base


def load_config(path: str | Path | list[str | Path], schema_path: str | Path = SCHEMA_PATH) -> dict:
    """Read a config file, or several merged in order (a base config, then overlays such as a
    campaign's), and validate the result; a missing, unreadable or malformed file is a ConfigError,
    and a problem is blamed on the file that sets the key."""
    paths = [Path(p) for p in ([path] if isinstance(path, (str, Path)) else path)]
    if not paths:
        raise ValueError("no config file given")
    config: dict = {}
    for p in paths:
        _merge(config, _read_yaml(p))
    return validate_config(config, schema_path, paths)
