"""Formula models from Python (docs/formula-models.md): the JSON object of a job's /model/formula, or a model file.

    from nonsep.formula import formula_model, write_formula_model
    job["model"] = {"formula": formula_model(T="p0^2/2", V="q0^2/2 + lam*q0^4", parameters={"lam": 0.1})}
    write_formula_model("quartic.json", T=p0**2 / 2, V=q0**2 / 2, name="quartic")   # SymPy expressions
    job["model"] = {"formula": formula_model(H="(p0 - q1)^2/2 + p1^2/2 + q0^2/2")}  # a Hamiltonian of any shape

H (a Hamiltonian H(q, p) of any shape), or T, V, K and U of the product form, are strings or SymPy expressions (anything whose str() is a formula: SymPy writes ** for powers,
which the grammar accepts). The host parses them with its strict grammar (`nonsep validate` reports a bad formula
at its column); nothing here checks them beyond turning SymPy's names for abs and e into the grammar's.
"""
import json
import re

__all__ = ["formula_model", "formula_text", "write_formula_model"]

_SYMPY_NAMES = [(re.compile(r"\bAbs\("), "abs("), (re.compile(r"\bE\b"), "exp(1)")]


def formula_text(expression):
    """The formula of a string (as it is) or of a SymPy expression (its str(), with Abs -> abs and E -> exp(1))."""
    if isinstance(expression, str):
        return expression
    text = str(expression)
    for pattern, replacement in _SYMPY_NAMES:
        text = pattern.sub(replacement, text)
    return text


def formula_model(T=None, V=None, *, H=None, K=None, U=None, parameters=None, dimension=None, name=None):
    """The object of /model/formula (or of a model file): either H(q, p) alone, or T(p) and V(q) with optionally the
    separable part K(p) + U(q); parameters {name: default}, the dimension and the plugin's name."""
    if H is not None and any(part is not None for part in (T, V, K, U)):
        raise ValueError("formula_model: give either H alone or T and V (with K and U), not both")
    if H is None and (T is None or V is None):
        raise ValueError("formula_model: give H, or both T and V")
    model = {}
    if name is not None:
        model["name"] = name
    if H is not None:
        model["H"] = formula_text(H)
    else:
        model["T"] = formula_text(T)
        model["V"] = formula_text(V)
    if K is not None:
        model["K"] = formula_text(K)
    if U is not None:
        model["U"] = formula_text(U)
    if parameters:
        model["parameters"] = {str(key): float(value) for key, value in parameters.items()}
    if dimension is not None:
        model["dimension"] = int(dimension)
    return model


def write_formula_model(path, T=None, V=None, **options):
    """Writes the model file `path` (JSON) for `"formula": "path"` in a job or `nonsep model compile`; returns path."""
    with open(path, "w", encoding="utf-8") as file:
        json.dump(formula_model(T, V, **options), file, indent=2)
        file.write("\n")
    return path
