"""The adaptive mixture of ray distributions (AGVS §4.2).

Each distribution's weight is its recent contribution per unit of cost (Eq. 3 and the weight
``w(D) = c_s(D) / t_s(D)``); the probability of drawing from it is its share of the weights
(Eq. 4).  The cost of a sample is counted in rays traced, not in seconds: the rays are most
of a sample's time, and a count keeps a run with a ray budget the same on every machine
(the seconds per distribution are reported beside).  "Recent" is an exponential average
over batches, :data:`MEMORY` of the weight on the last one.  Every distribution keeps at
least :data:`FLOOR` of the samples, so that one that stops paying is still tried, and the
view space-direction distribution at least :data:`UNIFORM_FLOOR`, since its rays are also
the random cameras of the pixel-error estimate (§4.5).

>>> mix = Mixture(("uniform", "two-point"))
>>> mix.update("uniform", contribution=5, rays=1000)
>>> mix.update("two-point", contribution=95, rays=1000)
>>> p = mix.probabilities({"uniform": True, "two-point": True})
>>> round(p["uniform"], 2), round(p["two-point"], 2)  # the uniform share lifted to its floor
(0.1, 0.9)
"""

from __future__ import annotations

#: weight of the last batch in the running averages of contribution and rays
MEMORY = 0.5
#: least share of the samples of every available distribution
FLOOR = 0.02
#: least share of the view space-direction distribution (the error estimate's cameras)
UNIFORM_FLOOR = 0.1


class Mixture:
    """Running contribution per ray of each distribution, and the probabilities they give.

    Parameters
    ----------
    names : sequence of str
        The distributions.
    """

    def __init__(self, names):
        self.names = tuple(names)
        self.contribution = dict.fromkeys(self.names, 0.0)
        self.rays = dict.fromkeys(self.names, 0.0)
        self.tried = dict.fromkeys(self.names, False)

    def update(self, name: str, contribution: float, rays: float) -> None:
        """Fold a batch of ``name`` (its new PVS entries and rays) into the running averages."""
        if rays <= 0:
            return
        if not self.tried[name]:
            self.contribution[name], self.rays[name] = float(contribution), float(rays)
            self.tried[name] = True
            return
        self.contribution[name] = (1 - MEMORY) * self.contribution[name] + MEMORY * contribution
        self.rays[name] = (1 - MEMORY) * self.rays[name] + MEMORY * rays

    def weight(self, name: str) -> float:
        """Contribution per ray (``w(D)``)."""
        return self.contribution[name] / self.rays[name] if self.rays[name] > 0 else 0.0

    def probabilities(self, available: dict[str, bool]) -> dict[str, float]:
        """Eq. 4 over the available distributions, with the floors; untried ones share equally."""
        names = [n for n in self.names if available.get(n, False)]
        if not names:
            return dict.fromkeys(self.names, 0.0)
        untried = [n for n in names if not self.tried[n]]
        if untried:  # a distribution not measured yet gets its first batch at an equal share
            raw = dict.fromkeys(names, 1.0)
        else:
            w = {n: self.weight(n) for n in names}
            total = sum(w.values())
            raw = {n: (w[n] / total if total > 0 else 1.0 / len(names)) for n in names}
        floor = {n: (UNIFORM_FLOOR if n == "uniform" else FLOOR) for n in names}
        total = sum(raw.values())
        p = {n: raw[n] / total for n in names}
        # lift the distributions below their floor, take the difference from the others
        low = {n for n in names if p[n] < floor[n]}
        rest = sum(p[n] for n in names if n not in low)
        spare = 1.0 - sum(floor[n] for n in low)
        out = {n: (floor[n] if n in low else p[n] / rest * spare if rest > 0 else 0.0) for n in names}
        return {n: out.get(n, 0.0) for n in self.names}
