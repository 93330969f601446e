"""rinscope from Python (work in progress on branch python-package): the presets and their validation.

Everything is computed by the Rust library; this package converts.
"""
from ._rinscope import scenarios, preset_toml, check  # noqa: F401
