"""The Python API reference (docs/src/python-api.md) from the installed package's docstrings:
    python .ci/python-api-reference.py > docs/src/python-api.md
`.ci/wheel-check` regenerates it from the wheel and fails if the committed page differs."""
import inspect

import armscope


def doc(obj):
    return inspect.cleandoc(obj.__doc__ or "").strip()


def signature(name, obj):
    try:
        text = str(inspect.signature(obj))
    except (TypeError, ValueError):
        text = getattr(obj, "__text_signature__", None) or "(…)"
    for self_arg, bare in [("(self, /, ", "("), ("(self, /)", "()"), ("($self, /, ", "("), ("($self, ", "("), ("(self)", "()")]:
        text = text.replace(self_arg, bare)
    return f"{name}{text}"


out = ["# Python API reference", "", "Generated from the `armscope` package's docstrings (`.ci/python-api-reference.py`).", ""]
out += [doc(armscope), ""]
for name in armscope.__all__:
    obj = getattr(armscope, name)
    if inspect.isclass(obj):
        out += [f"## `armscope.{name}`", ""]
        if not issubclass(obj, BaseException):
            out += [f"`{signature(name, obj)}`", ""]
        out += [doc(obj), ""]
        for member, value in sorted(vars(obj).items()):
            if member.startswith("_") or not (value.__doc__ or "").strip():
                continue
            kind = "property" if isinstance(value, property) or type(value).__name__ == "getset_descriptor" else "method"
            title = f"`{name}.{member}`" if kind == "property" else f"`{signature(name + '.' + member, value)}`"
            out += [f"### {title}", "", doc(value), ""]
    else:
        out += [f"## `{signature('armscope.' + name, obj)}`", "", doc(obj), ""]
print("\n".join(out).rstrip() + "\n", end="")
