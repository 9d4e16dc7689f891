"""Sphinx configuration of the fastsim_ros user guide.

Build: ``.venv/bin/python -m sphinx -W -b html docs docs/_build/html`` from the
package root (``test/test_docs.py`` builds it the same way into a temporary
directory).  The pages are Markdown (MyST); the parameters table is generated
at build time from :data:`fastsim_ros.ros.params.PARAMETERS` by ``_ext/params_table.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

project = "fastsim_ros"
author = "fastsim_ros maintainers"
copyright = "fastsim_ros maintainers"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "params_table",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "data", "figures/*.csv", "Thumbs.db", ".DS_Store"]

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

# The ROS client library is not needed to read the docstrings: the modules that
# import it are documented with it mocked.
autodoc_mock_imports = ["rclpy", "rosidl_runtime_py", "builtin_interfaces",
                        "geometry_msgs", "sensor_msgs", "std_msgs", "diagnostic_msgs",
                        "visualization_msgs", "lifecycle_msgs", "rcl_interfaces"]
autodoc_default_options = {"members": True, "undoc-members": False}
autodoc_typehints = "none"
autodoc_member_order = "bysource"

# Straight quotes: the pages quote code, parameter values and messages verbatim.
smartquotes = False

html_theme = "alabaster"
html_static_path: list[str] = []
html_title = "fastsim_ros"
