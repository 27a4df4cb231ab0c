"""Drawings (design notes §8): a DXF turning drawing read tolerantly into its profile, operations
and cutting data, or refused with one line that says why. Below the turning models, which plan
jobs from what is read here."""
