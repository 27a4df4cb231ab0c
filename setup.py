"""The packages engine/ and importers/ (design notes §3), and the top-level data folders
(migrations/, schema/, seed_templates/), which ship inside the wheel as the package engine_data
that engine.paths finds with importlib; the web view's page templates ship inside engine.service.web.
Everything else about the project is in pyproject.toml."""
from setuptools import find_packages, setup

DATA_FOLDERS = {"engine_data.migrations": "migrations", "engine_data.schema": "schema",
                "engine_data.seed_templates": "seed_templates",
                "engine_data.seed_templates.classes": "seed_templates/classes",
                "engine_data.seed_templates.drawings": "seed_templates/drawings"}

setup(packages=find_packages(include=["engine", "engine.*", "importers", "importers.*"]) + list(DATA_FOLDERS),
      package_dir=DATA_FOLDERS,
      package_data={"engine": ["py.typed"], "engine.service.web": ["templates/*.html", "static/*"],
                    **{package: ["*.sql", "*.csv", "*.json", "*.md", "*.dxf"]
                                               for package in DATA_FOLDERS}})
