"""rinscope from Python (work in progress on branch python-package): the presets and their validation.

Everything is computed by the Rust library; this package converts.
"""
import json as _json

from ._rinscope import scenarios, preset_toml, check  # noqa: F401
from . import _rinscope


def run_summary(scenario, save, duration_s=None):
    """Runs a preset (by name) or a scenario's TOML text, saves the recording, returns the summary dict."""
    toml = preset_toml(scenario) if "\n" not in scenario else scenario
    return _json.loads(_rinscope.run_summary(toml, str(save), duration_s))
