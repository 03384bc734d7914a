"""A score's running typical value, for telling a subject's usual look from a failing model's."""
from __future__ import annotations


class RunningTypical:
    """The typical value of a score on the subject: its first value, then an exponential average of
    the values at ``learn_above`` of it or more, so it does not sink while the subject is gone."""

    def __init__(self, rate: float = 0.05, learn_above: float = 0.6) -> None:
        self.rate = rate
        self.learn_above = learn_above
        self.value = 0.0

    def reset(self) -> None:
        self.value = 0.0

    def relative(self, score: float) -> float:
        """``score`` over the typical value (1 while none is known); learns from it where it is high
        enough."""
        if self.value <= 0.0:
            self.value = score
            return 1.0
        relative = score / self.value
        if relative >= self.learn_above:
            self.value += self.rate * min(relative, 1.0) * (score - self.value)
        return relative

    def ratio(self, score: float) -> float:
        """``score`` over the typical value without learning from it (1 while none is known)."""
        return score / self.value if self.value > 0.0 else 1.0
