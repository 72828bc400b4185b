"""A campaign on synthetic data against what was hidden in it: was every hidden effect named, and
does its calibrated value lie within a few standard uncertainties of the value the data were made
with?  The check behind the claim that the diagnosis finds a missing effect, on data whose answer
is known (``hdwf synth``; a campaign's ``hidden_effects`` in ``config.yaml``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

# A found value counts as recovered within this many of its standard uncertainties of the hidden
# one: three, so that a correct calibration fails by chance about once in 400 (normal errors).
RECOVERED_WITHIN_SD = 3.0


@dataclass(frozen=True)
class HiddenParameter:
    """One hidden parameter against the campaign's finding (``found`` None: effect not named)."""

    effect: str
    param: str
    hidden: float
    found: float | None
    sd: float | None           # the found value's standard uncertainty, where the diagnosis gives one

    @property
    def off_by_sd(self) -> float | None:
        """(found − hidden) in standard uncertainties, or None without a finding or an uncertainty."""
        if self.found is None or not self.sd:
            return None
        return (self.found - self.hidden) / self.sd

    @property
    def recovered(self) -> bool:
        """Named, and within ``RECOVERED_WITHIN_SD`` of the hidden value (exactly equal without an sd)."""
        if self.found is None:
            return False
        if not self.sd:
            return self.found == self.hidden
        return abs(self.off_by_sd) <= RECOVERED_WITHIN_SD

    def to_dict(self) -> dict:
        return {**asdict(self), "off_by_sd": self.off_by_sd, "recovered": self.recovered}


@dataclass(frozen=True)
class Recovery:
    """Every hidden parameter against the finding, and the effects named that were not hidden."""

    parameters: tuple[HiddenParameter, ...]
    not_hidden: tuple[str, ...]        # named by the campaign, not in the data

    @property
    def all_recovered(self) -> bool:
        return all(p.recovered for p in self.parameters) and not self.not_hidden

    def to_dict(self) -> dict:
        return {"within_sd": RECOVERED_WITHIN_SD, "parameters": [p.to_dict() for p in self.parameters],
                "not_hidden": list(self.not_hidden), "all_recovered": self.all_recovered}


def recovery(hidden: dict[str, dict[str, float]], found: list[dict]) -> Recovery:
    """Hold a campaign's found effects against the hidden ones.

    Parameters
    ----------
    hidden : dict
        ``{effect: {parameter: value}}`` the data were made with.
    found : list of dict
        ``diagnosis.json``'s ``found``: per effect ``effect``, ``params`` and ``param_sd`` (the
        final, recalibrated values).

    Returns
    -------
    Recovery
        One ``HiddenParameter`` per hidden parameter, in the order given, and the effects found
        that were not hidden.
    """
    by_effect = {f["effect"]: f for f in found}
    params = []
    for effect, values in hidden.items():
        f = by_effect.get(effect)
        for param, value in values.items():
            got = None if f is None else f["params"].get(param)
            sd = None if f is None or len(f["params"]) != 1 else f.get("param_sd")
            params.append(HiddenParameter(effect, param, float(value), None if got is None else float(got),
                                          None if sd is None else float(sd)))
    return Recovery(tuple(params), tuple(e for e in by_effect if e not in hidden))
