"""The effect catalogue and the loop: diagnose which physical effect is missing, add it, improve."""
from twin.effects.catalogue import CATALOGUE, Effect, FitParameter, effect
from twin.effects.variant import (CANDIDATES_MODEL, candidates_source, variant_name, variant_source,
                                  write_variant)

__all__ = ["CATALOGUE", "Effect", "FitParameter", "effect", "CANDIDATES_MODEL", "candidates_source",
           "variant_name", "variant_source", "write_variant"]
