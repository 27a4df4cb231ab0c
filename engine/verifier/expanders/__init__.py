"""The expanders of the dialects that have one (engine.verifier.expansion): each module registers
its function under the name its Dialect row gives. Nothing is imported here: expansion.expand
imports a dialect's module (expansion.EXPANDER_MODULES) on its first program, so a command that
reads only 840D hobbing programs loads none of the lathe interpreters (issue 28); a dialect whose
expander no module registers is refused."""
