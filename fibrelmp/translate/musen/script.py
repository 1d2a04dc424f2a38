"""cmusen job scripts: ``script_parse`` reads them (jobs, keywords, line numbers),
``script_settings`` applies a SIMULATOR job to a scene.  The names both offer, in one place."""

from fibrelmp.translate.musen.script_parse import (COMPONENTS, INTERACTION_PROPERTIES, MATERIAL_PROPERTIES,
                                                   MUSEN_MODELS, OTHER_COMPONENTS,
                                                   MusenJob, MusenModelSpec, check_patch, model_kind, read,
                                                   read_script)
from fibrelmp.translate.musen.script_settings import (MUSEN_DEFAULTS, apply_simulator_settings,
                                                      recommended_time_step, reset_bond_lengths)

__all__ = ["COMPONENTS", "INTERACTION_PROPERTIES", "MATERIAL_PROPERTIES", "MUSEN_DEFAULTS",
           "MUSEN_MODELS", "OTHER_COMPONENTS", "MusenJob", "MusenModelSpec",
           "apply_simulator_settings", "check_patch", "model_kind", "read", "read_script",
           "recommended_time_step", "reset_bond_lengths"]
