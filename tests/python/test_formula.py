"""nonsep.formula: models from strings and SymPy expressions, checked by `nonsep validate` (which does not compile)."""
import json
import os
import tempfile
import unittest

import sympy

import nonsep
from nonsep.formula import formula_model, formula_text, write_formula_model


def job(model):
    return {"model": {"formula": model}, "integrator": {"scheme": "triplet", "order": "4/3"},
            "initial": {"q": [0.5], "p": [0.0]}, "time": {"dt": 0.01, "steps": 10}}


class FormulaTest(unittest.TestCase):
    def test_sympy_expressions_become_formulas_the_host_accepts(self):
        q0, p0, lam = sympy.symbols("q0 p0 lam")
        model = formula_model(T=p0**2 / 2, V=q0**2 / 4 + lam * sympy.Abs(q0)**3 * sympy.E,
                              parameters={"lam": 0.5}, name="sympy_model")
        self.assertEqual(model["T"], "p0**2/2")
        self.assertIn("abs(q0)**3", model["V"])
        self.assertIn("exp(1)", model["V"])
        self.assertEqual(nonsep.validate(job(model)), [])

    def test_strings_pass_through_and_a_bad_formula_is_reported_at_its_column(self):
        self.assertEqual(formula_text("q0^2"), "q0^2")
        problems = nonsep.validate(job(formula_model(T="p0^2/2", V="q0^2 + ; q0")))
        self.assertEqual(len(problems), 1)
        self.assertEqual(problems[0].path, "/model/formula/V")
        self.assertIn("column 8", problems[0].message)

    def test_a_model_file_named_by_a_job(self):
        with tempfile.TemporaryDirectory() as folder:
            path = write_formula_model(os.path.join(folder, "model.json"), T="p0^2/2", V="q0^2/2", name="harmonic")
            with open(path, encoding="utf-8") as file:
                self.assertEqual(json.load(file), {"name": "harmonic", "T": "p0^2/2", "V": "q0^2/2"})
            self.assertEqual(nonsep.validate(job(path)), [])

    def test_a_hamiltonian_of_any_shape(self):
        q0, q1, p0, p1 = sympy.symbols("q0 q1 p0 p1")
        model = formula_model(H=(p0 - q1)**2 / 2 + p1**2 / 2 + q0**2 / 2, name="gauge")
        self.assertEqual(set(model), {"name", "H"})
        gauss = dict(job(model), integrator={"scheme": "gauss", "stages": 3},
                     initial={"q": [0.5, 0.0], "p": [0.0, 0.1]})
        self.assertEqual(nonsep.validate(gauss), [])
        # Chin's schemes need the product form: refused before anything is compiled.
        problems = nonsep.validate(dict(gauss, integrator={"scheme": "triplet", "order": "4/3"}))
        self.assertEqual([problem.path for problem in problems], ["/integrator/scheme"])
        self.assertIn("product form", problems[0].message)
        with self.assertRaises(ValueError):
            formula_model(H="p0^2/2", T="p0^2/2")
        with self.assertRaises(ValueError):
            formula_model(T="p0^2/2")


if __name__ == "__main__":
    unittest.main()
