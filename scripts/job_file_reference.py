#!/usr/bin/env python3
"""Writes docs/job-file.md, the key-by-key reference of job files, from schemas/job.schema.json.

    python3 scripts/job_file_reference.py            # regenerates docs/job-file.md from the schema
    python3 scripts/job_file_reference.py --check    # exit 1 when docs/job-file.md is not what the schema gives

Python 3 standard library only. Every key of the schema gets one row per place it can appear: its path (array
elements as `[]`, a plugin parameter as `<name>`), the condition under which it applies (a scheme, a run or a
study), its type, its default (or **required**), the values allowed (enum, range, length, pattern) and the
schema's description of it. The schema itself is `nonsep schema`'s output, generated from the job reader's key
tables and the scheme catalogue; a test (`docs.job_file_reference`) fails when the two files disagree.
Exit status: 0 written or up to date, 1 out of date (--check), 2 unreadable schema, a schema keyword this script
does not know, or a description or key of the schema the reference would not show (each named), so that nothing
of the schema can be left out of the reference silently.
"""
import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LARGEST_DOUBLE = sys.float_info.max
LARGEST_INT64 = 2**63 - 1

# Keywords this script renders; any other in the schema is an error (exit 2).
KNOWN = {"$schema", "$id", "title", "description", "type", "additionalProperties", "required", "properties", "allOf",
         "$defs", "$ref", "minLength", "maxLength", "pattern", "propertyNames", "default", "enum", "minimum", "maximum", "exclusiveMinimum", "not",
         "const", "oneOf", "anyOf", "if", "then", "else", "items", "minItems", "maxItems", "uniqueItems", "examples",
         "dependentRequired", "dependentSchemas"}


class SchemaError(Exception):
    pass


class Reference:
    def __init__(self, schema):
        self.schema = schema
        self.rows = []  # (section, path, when, type, default, allowed, description)

    # ---- reading the schema

    def resolve(self, node):
        """`node` with its $ref (recursively) merged under its own keys."""
        if node is True:
            return {}
        unknown = set(node) - KNOWN
        if unknown:
            raise SchemaError(f"unknown schema keyword(s) {sorted(unknown)} in {json.dumps(node)[:200]}")
        if "$ref" not in node:
            return node
        target = node["$ref"]
        prefix = "#/$defs/"
        if not target.startswith(prefix) or target[len(prefix):] not in self.schema["$defs"]:
            raise SchemaError(f"unresolvable $ref {target}")
        merged = dict(self.resolve(self.schema["$defs"][target[len(prefix):]]))
        if "not" in merged and "not" in node:
            merged["not"] = {"allOf": [merged["not"], node["not"]]}
        elif "not" in node:
            merged["not"] = node["not"]
        base_description = merged.get("description")
        merged.update({k: v for k, v in node.items() if k not in ("$ref", "not")})
        if base_description and merged.get("description") != base_description:
            merged["description"] = f"{sentence(merged['description'])} {base_description}"  # key's, then shape's
        return merged

    def type_text(self, node):
        node = self.resolve(node)
        if "const" in node:
            return "constant"
        if "enum" in node:
            kinds = {type(v).__name__ for v in node["enum"]}
            return "string" if kinds == {"str"} else "one of the values"
        if node.get("type") == "array" and "items" in node:
            plural = {"number": "numbers", "integer": "integers", "object": "objects", "string": "strings"}
            items = self.type_text(node["items"]).split(" or ")
            return "array of " + " or ".join(plural.get(item, item) for item in items)
        if "oneOf" in node and "type" not in node:
            texts = []
            for alternative in node["oneOf"]:
                text = self.type_text(alternative)
                if text not in texts:
                    texts.append(text)
            return " or ".join(texts)
        kind = node.get("type")
        if isinstance(kind, list):
            return " or ".join(kind)
        return kind or "any"

    def allowed_text(self, node):
        node = self.resolve(node)
        parts = []
        if "enum" in node:
            parts.append(", ".join(f"`{json.dumps(v)}`" for v in node["enum"]))
        if "const" in node:
            parts.append(f"`{json.dumps(node['const'])}`")
        low, high = node.get("minimum"), node.get("maximum")
        if low == -LARGEST_DOUBLE and high == LARGEST_DOUBLE:
            parts.append("finite")
        elif low == -LARGEST_DOUBLE:
            parts.append(f"finite, ≤ {number(high)}")
        elif high == LARGEST_DOUBLE:
            parts.append(f"finite, ≥ {number(low)}")
        elif low is not None and high is not None and high != LARGEST_INT64:
            parts.append(f"{number(low)} to {number(high)}")
        elif low is not None:
            parts.append(f"≥ {number(low)}")
        elif high is not None:
            parts.append(f"≤ {number(high)}")
        if "exclusiveMinimum" in node:
            parts.append(f"> {number(node['exclusiveMinimum'])}")
        if "not" in node and not is_object(node):
            parts.append(self.negation_text(node["not"]))
        if node.get("minLength") == 1:
            parts.append("non-empty")
        elif "minLength" in node:
            parts.append(f"at least {node['minLength']} characters")
        if "maxLength" in node:
            parts.append(f"at most {node['maxLength']} characters")
        if "propertyNames" in node:
            parts.append(f"keys match `{node['propertyNames']['pattern']}`")
        if "pattern" in node:
            pattern = node["pattern"]
            parts.append("no NUL character" if pattern == "^[^\\u0000]*$" else f"matches `{pattern}`")
        if node.get("type") == "array" or "items" in node:
            low_items, high_items = node.get("minItems"), node.get("maxItems")
            if low_items is not None and high_items is not None:
                parts.append(f"{number(low_items)} to {number(high_items)} elements")
            elif low_items == 1:
                parts.append("non-empty")
            elif low_items is not None:
                parts.append(f"at least {low_items} elements")
            if node.get("uniqueItems"):
                parts.append("distinct elements")
            if "items" in node:
                item = self.allowed_text(node["items"])
                if item:
                    parts.append(f"each {item}")
        if "oneOf" in node and "type" not in node:
            alternatives = [(self.type_text(a), self.allowed_text(a)) for a in node["oneOf"]]
            parts.append("; or ".join(f"{kind}: {text}" for kind, text in alternatives if text))
        if "examples" in node:
            parts.append("this scheme's orders: " + ", ".join(f"`{json.dumps(v)}`" for v in node["examples"]))
        return "; ".join(p for p in parts if p)

    def negation_text(self, node):
        if "allOf" in node:
            return "; ".join(self.negation_text(n) for n in node["allOf"])
        if "const" in node:
            return f"not {json.dumps(node['const'])}"
        if set(node) == {"required"}:
            keys = node["required"]
            return "not " + " and ".join(f"`{k}`" for k in keys) + (" together" if len(keys) > 1 else "")
        if set(node) == {"anyOf"} and all(set(n) == {"required"} for n in node["anyOf"]):
            keys = [k for n in node["anyOf"] for k in n["required"]]
            return "none of " + ", ".join(f"`{k}`" for k in keys)
        raise SchemaError(f"a 'not' this script cannot put in words: {json.dumps(node)}")

    def object_rules(self, node):
        """The constraints of an object among its keys, in words."""
        rules = []
        if "oneOf" in node and all(set(n) == {"required"} for n in node["oneOf"]):
            keys = [k for n in node["oneOf"] for k in n["required"]]
            rules.append("exactly one of " + ", ".join(f"`{k}`" for k in keys))
        if "not" in node:
            rules.append(self.negation_text(node["not"]))
        for key, needed in node.get("dependentRequired", {}).items():
            rules.append(f"`{key}` needs " + ", ".join(f"`{k}`" for k in needed))
        for key, schema in node.get("dependentSchemas", {}).items():
            if set(schema) == {"not"} and set(schema["not"]) == {"required"} and len(schema["not"]["required"]) == 1:
                rules.append(f"not `{schema['not']['required'][0]}` and `{key}` together")
            else:
                rules.append(f"with `{key}`: {self.negation_text(schema['not'])}")
        return rules

    def condition_text(self, node, negated=False):
        if set(node) == {"required"}:
            keys = ", ".join(f"`{k}`" for k in node["required"])
            return ("without " if negated else "with ") + keys
        if set(node) == {"properties"} and len(node["properties"]) == 1:
            (key, value), = node["properties"].items()
            if set(value) == {"const"}:
                return f"`{key}` {'≠' if negated else '='} `{json.dumps(value['const'])}`"
        raise SchemaError(f"an 'if' this script cannot put in words: {json.dumps(node)}")

    # ---- walking it

    def walk(self, node, path, when, required, section, description=None):
        node = self.resolve(node)
        text = description if description is not None else node.get("description", "")
        extra = self.object_rules(node) if is_object(node) else []
        if "oneOf" in node and "type" not in node:
            described = [self.resolve(a) for a in node["oneOf"]]
            forms = [f"{self.type_text(a)}: {a['description'].rstrip('.')}" for a in described if a.get("description")]
            if forms:
                text = f"{sentence(text)} Either " + "; or ".join(forms) + "."
        if "items" in node and "oneOf" in self.resolve(node["items"]):
            described = [self.resolve(a) for a in self.resolve(node["items"])["oneOf"]]
            forms = [f"{self.type_text(a)}: {a['description'].rstrip('.')}" for a in described if a.get("description")]
            if forms:
                text = f"{sentence(text)} Each element is either " + "; or ".join(forms) + "."
        if path:
            default = "**required**" if required else (f"`{json.dumps(node['default'])}`" if "default" in node else "")
            allowed = "; ".join([self.allowed_text(node)] + extra).strip("; ")
            self.rows.append((section, path, when, self.type_text(node), default, allowed, text))
        self.children(node, path, when, section)

    def properties(self, node, path, when, section):
        required = set(node.get("required", []))
        for key, child in node.get("properties", {}).items():
            if child is not True:
                self.walk(child, f"{path}.{key}" if path else key, when, key in required, section or key)

    def children(self, node, path, when, section):
        self.properties(node, path, when, section)
        extra = node.get("additionalProperties")
        if isinstance(extra, dict):
            self.walk(extra, f"{path}.<name>", when, False, section)
        if "items" in node:
            item = self.resolve(node["items"])
            if is_object(item) and (item.get("description") or self.object_rules(item)):
                self.rows.append((section, f"{path}[]", when, "object", "", "; ".join(self.object_rules(item)),
                                  item.get("description", "")))
            if "properties" in item or "oneOf" in item or "allOf" in item:
                self.children_of_alternative(item, f"{path}[]", when, section)
        if "oneOf" in node and "type" not in node:
            for alternative in node["oneOf"]:
                alternative = self.resolve(alternative)
                if alternative.get("type") == "array":
                    self.children(alternative, path, when, section)
                else:
                    self.children_of_alternative(alternative, path, when, section)
        for branch in node.get("allOf", []):
            if "if" not in branch:
                raise SchemaError(f"an allOf entry without 'if': {json.dumps(branch)[:200]}")
            for key, negated in (("then", False), ("else", True)):
                if key not in branch:
                    continue
                condition = self.condition_text(branch["if"], negated)
                sub = self.resolve(branch[key])
                branch_when = f"{when}, {condition}" if when else condition
                if sub.get("description"):
                    rules = self.object_rules(sub)
                    self.rows.append((section, path or "(document)", branch_when, "object", "",
                                      "; ".join(rules), sub["description"]))
                elif not path and (self.object_rules(sub) or sub.get("required")):
                    rules = self.object_rules(sub)
                    if sub.get("required"):
                        rules.append("requires " + ", ".join(f"`{k}`" for k in sub["required"]))
                    self.rows.append(("(document)", "(document)", branch_when, "object", "", "; ".join(rules), ""))
                elif self.object_rules(sub) or sub.get("required"):
                    raise SchemaError(f"constraints without a description at {path}: {json.dumps(sub)[:200]}")
                self.properties(sub, path, branch_when, section)

    def children_of_alternative(self, node, path, when, section):
        if any(key in node for key in ("properties", "allOf", "items", "oneOf")):
            self.children(node, path, when, section)


def sentence(text):
    return text if not text or text.endswith((".", ")")) else text + "."


def is_object(node):
    return node.get("type") == "object" or "properties" in node


def merged(rows):
    """Rows that differ only in the scheme they apply to, as one row naming the schemes, where the first stood."""
    scheme = re.compile(r'^(.*?)(?:, )?`scheme` = (`"[^`]*"`)$')
    out, index = [], {}
    for section, path, when, kind, default, allowed, description in rows:
        match = scheme.match(when)
        if not match or not path.endswith(tuple(f".{k}" for k in ("order", "t2", "omega", "stages", "max_iterations",
                                                                   "label", "steps", "dt"))):
            out.append([section, path, when, kind, default, allowed, description])
            continue
        key = (section, path, match.group(1), kind, default, allowed, description)
        if key in index:
            out[index[key]][2].append(match.group(2))
        else:
            index[key] = len(out)
            out.append([section, path, [match.group(2)], kind, default, allowed, description])
            out[-1].append(match.group(1))
    rows = []
    for row in out:
        if isinstance(row[2], list):
            prefix = row.pop()
            condition = f"`scheme` = {row[2][0]}" if len(row[2]) == 1 else "`scheme` one of " + ", ".join(row[2])
            row[2] = f"{prefix}, {condition}" if prefix else condition
        rows.append(tuple(row))
    return rows


def number(value):
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, int) and abs(value) >= 10**6 and str(value).rstrip("0") == "1":
        return f"10^{len(str(value)) - 1}"
    return str(value)


def cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def missing(schema, text):
    """What of the schema the reference leaves out: each description that is not in `text`, and each key (a
    property name) that no row's path ends in."""
    descriptions, keys = [], set()

    def collect(node):
        if isinstance(node, dict):
            if isinstance(node.get("description"), str):
                descriptions.append(node["description"])
            for key, value in node.items():
                if key == "properties" and isinstance(value, dict):
                    keys.update(value)
                collect(value)
        elif isinstance(node, list):
            for value in node:
                collect(value)

    collect(schema)
    lost = [f"description {d[:60]!r}" for d in descriptions if cell(d.rstrip(".")) not in text]
    lost += [f"key {k}" for k in sorted(keys) if not re.search(rf"`([^`|]*\.)?{re.escape(k)}` \|", text)]
    return lost


def render(schema):
    reference = Reference(schema)
    reference.walk(schema, "", "", False, "")
    lines = [
        "# Job files, key by key",
        "",
        "<!-- Generated by scripts/job_file_reference.py from schemas/job.schema.json; do not edit. Regenerate with",
        "     python3 scripts/job_file_reference.py (the test docs.job_file_reference fails when this file differs). -->",
        "",
        schema["description"],
        "",
        "A job file is one JSON object; unknown keys and duplicate keys are errors everywhere. Paths below join keys",
        "with `.`; `[]` stands for every element of an array and `<name>` for any key. *When* says under which",
        "condition a row applies: a scheme (`scheme` = ...), a run (without `study`) or a study (with `study`).",
        "Numbers are finite wherever a number is allowed; integers are at most 2^63 − 1 unless a smaller maximum is",
        "given, and an integral number such as `10.0` counts as an integer. `nonsep validate JOB.json` checks a job",
        "completely, including what the schema cannot express (the plugin's parameters and dimension, a scheme's",
        "orders, the signs of `dt` and `t_end`); [user-guide.md](user-guide.md) explains each part with examples.",
    ]
    sections = []
    rows = merged(reference.rows)
    for row in rows:
        if row[0] not in sections:
            sections.append(row[0])
    for section in sections:
        lines += ["", f"## `{section}`" if section != "(document)" else "## The document as a whole", "", "| key | when | type | default | allowed | description |",
                  "|---|---|---|---|---|---|"]
        for _, path, when, kind, default, allowed, description in rows:
            if _ == section:
                lines.append("| " + " | ".join(cell(x) for x in (f"`{path}`", when, kind, default, allowed,
                                                                   description)) + " |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--schema", type=Path, default=ROOT / "schemas" / "job.schema.json")
    parser.add_argument("--output", type=Path, default=ROOT / "docs" / "job-file.md")
    parser.add_argument("--check", action="store_true", help="compare instead of writing; exit 1 when they differ")
    arguments = parser.parse_args()
    try:
        schema = json.loads(arguments.schema.read_text(encoding="utf-8"))
        text = render(schema)
        lost = missing(schema, text)
        if lost:
            raise SchemaError("the reference would leave out " + ", ".join(lost))
    except (OSError, ValueError, SchemaError) as error:
        print(f"job_file_reference: {arguments.schema}: {error}", file=sys.stderr)
        return 2
    if arguments.check:
        current = arguments.output.read_text(encoding="utf-8") if arguments.output.exists() else None
        if current != text:
            print(f"job_file_reference: {arguments.output} is not what {arguments.schema} gives"
                  f"{' (missing)' if current is None else ''}; regenerate it with "
                  f"`python3 scripts/job_file_reference.py`", file=sys.stderr)
            return 1
        return 0
    arguments.output.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
