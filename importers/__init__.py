"""Importers that turn outside files into jobs and templates."""
