"""A campaign on synthetic data against what was hidden in it: was every hidden effect named, and
does its calibrated value lie within a few standard uncertainties of the value the data were made
with?  The check behind the claim that the diagnosis finds a missing effect, on data whose answer
is known (``hdwf synth``; a campaign's ``hidden_effects`` in ``config.yaml``)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

# A found value counts as recovered within this many of its standard uncertainties of the hidden
# one: three, so that a correct calibration fails by chance about once in 400 (normal errors).
RECOVERED_WITHIN_SD = 3.0


@dataclass(frozen=True)
class HiddenParameter:
    """One hidden parameter against the campaign's finding."""

    effect: str
    param: str
    hidden: float
    found: float | None        # its final calibrated value; None: the effect was never calibrated
    sd: float | None           # that value's standard uncertainty, where the diagnosis gives one
    named: bool                # the search named the effect (not one the campaign was told to calibrate)

    @property
    def off_by_sd(self) -> float | None:
        """(found − hidden) in standard uncertainties; None without a value or a finite, positive sd
        (a singular fit's is infinite: it says nothing about where the value lies)."""
        if self.found is None or self.sd is None or not (math.isfinite(self.sd) and self.sd > 0):
            return None
        return (self.found - self.hidden) / self.sd

    @property
    def recovered(self) -> bool:
        """Named by the search, and within ``RECOVERED_WITHIN_SD`` of the hidden value."""
        off = self.off_by_sd
        return self.named and off is not None and abs(off) <= RECOVERED_WITHIN_SD

    def to_dict(self) -> dict:
        return {**asdict(self), "off_by_sd": self.off_by_sd, "recovered": self.recovered}


@dataclass(frozen=True)
class Recovery:
    """Every hidden parameter against the finding, and the effects named that were not hidden."""

    parameters: tuple[HiddenParameter, ...]
    not_hidden: tuple[str, ...]        # named by the search, not in the data

    @property
    def every_hidden_recovered(self) -> bool:
        return all(p.recovered for p in self.parameters)

    @property
    def all_recovered(self) -> bool:
        """Every hidden parameter recovered and nothing named that was not hidden."""
        return self.every_hidden_recovered and not self.not_hidden

    def to_dict(self) -> dict:
        return {"within_sd": RECOVERED_WITHIN_SD, "parameters": [p.to_dict() for p in self.parameters],
                "not_hidden": list(self.not_hidden), "every_hidden_recovered": self.every_hidden_recovered,
                "all_recovered": self.all_recovered}


def recovery(hidden: dict[str, dict[str, float]], found: list[dict], named: list[str]) -> Recovery:
    """Hold a campaign's found effects against the hidden ones.

    Parameters
    ----------
    hidden : dict
        ``{effect: {parameter: value}}`` the data were made with.
    found : list of dict
        ``diagnosis.json``'s ``found``: per effect ``effect``, ``params`` and ``param_sd`` (the
        final, recalibrated values), the effects the campaign was told to calibrate among them.
    named : list of str
        The effects the search named (``verdict.found_in_order``).

    Returns
    -------
    Recovery
        One ``HiddenParameter`` per hidden parameter, in the order given, and the effects named
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
                                          None if sd is None else float(sd), effect in named))
    return Recovery(tuple(params), tuple(e for e in named if e not in hidden))
