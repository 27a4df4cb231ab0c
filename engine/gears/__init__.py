"""Workpieces and what a hobbing job is made of (design notes §6): gear records and import,
duplex units, classification, the hob library and hob matching, the machining history and
cutting data, and which hobbing model serves which class."""
