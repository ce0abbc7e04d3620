"""The effect catalogue and the loop: diagnose which physical effect is missing, add it, improve."""
from twin.effects.catalogue import CATALOGUE, Effect, FitParameter, effect
from twin.effects.variant import (BASE_MODELS, CANDIDATES_MODEL, base_of, candidates_model, candidates_source,
                                  variant_name, variant_source, write_variant)

__all__ = ["CATALOGUE", "Effect", "FitParameter", "effect", "BASE_MODELS", "CANDIDATES_MODEL", "base_of",
           "candidates_model", "candidates_source", "variant_name", "variant_source", "write_variant"]
