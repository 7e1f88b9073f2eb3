#!/usr/bin/env python3
"""Write hostile-size inputs for substratec into the directory given as argv[1].

The files are large (up to 80 MB) and must not be committed: generate them into a
build or temporary directory, e.g.

    python3 tests/bad/generate_hostile.py build/hostile

Each file is described in tests/bad/README.md. On success the script prints nothing
and exits 0.
"""
import os
import sys

MiB = 1024 * 1024

HEAD = (
    '{\n'
    '  "format": "substrate-material/1",\n'
    '  "name": "m",\n'
    '  "inputs": {\n'
    '    "tint": { "type": "color", "default": [0.8, 0.1, 0.1] },\n'
    '    "mask": { "type": "float", "default": 0.5, "min": 0, "max": 1 }\n'
    '  },\n'
)


def write_chunks(path, parts):
    """Write an iterable of str parts to path (UTF-8), without building one big string."""
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        for p in parts:
            f.write(p)


def repeat(s, n, chunk=1 << 16):
    """Yield s repeated n times, in large pieces."""
    block = s * chunk
    full, rest = divmod(n, chunk)
    for _ in range(full):
        yield block
    if rest:
        yield s * rest


def deep_array(path):
    # 300000 opening brackets and nothing else: a recursive parser overflows its stack.
    write_chunks(path, [*repeat("[", 300_000), "\n"])


def deep_object(path):
    # {"a":{"a":...0...}} nested 300000 deep; well-formed, so only a depth limit stops it.
    n = 300_000
    write_chunks(path, [*repeat('{"a":', n), "0", *repeat("}", n), "\n"])


def deep_inline_nodes(path):
    # A material whose roughness is saturate(saturate(...(0.5)...)) 100000 deep.
    n = 100_000
    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        '    "base": { "kind": "slab", "diffuse_albedo": "$tint", "roughness": ',
        *repeat('{"kind": "saturate", "x": ', n), "0.5", *repeat("}", n),
        " }\n",
        "  },\n",
        '  "output": "base"\n',
        "}\n",
    ])


def many_nodes(path):
    # 100000 named math `add` nodes, each adding 0.00001 to the previous one.
    n = 100_000

    def nodes():
        yield '    "n000000": { "kind": "add", "a": "$mask", "b": 0.00001 },\n'
        for i in range(1, n):
            yield f'    "n{i:06d}": {{ "kind": "add", "a": "n{i - 1:06d}", "b": 0.00001 }},\n'

    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        *nodes(),
        '    "base": { "kind": "slab", "diffuse_albedo": "$tint", '
        f'"roughness": {{ "kind": "saturate", "x": "n{n - 1:06d}" }} }}\n',
        "  },\n",
        '  "output": "base"\n',
        "}\n",
    ])


def huge_string(path):
    # `name` is a 20 MiB identifier ("aaaa...").
    write_chunks(path, [
        '{\n  "format": "substrate-material/1",\n  "name": "',
        *repeat("a", 20 * MiB),
        '",\n'
        '  "inputs": { "tint": { "type": "color", "default": [0.8, 0.1, 0.1] } },\n'
        '  "nodes": { "base": { "kind": "slab", "diffuse_albedo": "$tint", "roughness": 0.5 } },\n'
        '  "output": "base"\n'
        "}\n",
    ])


def big_file(path):
    # 80 MiB: a complete valid material, then a "$schema" member (an allowed key) whose
    # string value pads the file to exactly 80 MiB. Well-formed; only a size limit rejects it.
    prefix = (
        '{\n'
        '  "format": "substrate-material/1",\n'
        '  "name": "m",\n'
        '  "inputs": { "tint": { "type": "color", "default": [0.8, 0.1, 0.1] } },\n'
        '  "nodes": { "base": { "kind": "slab", "diffuse_albedo": "$tint", "roughness": 0.5 } },\n'
        '  "output": "base",\n'
        '  "$schema": "'
    )
    suffix = '"\n}\n'
    pad = 80 * MiB - len(prefix) - len(suffix)
    write_chunks(path, [prefix, *repeat("x", pad), suffix])


def long_identifier(path):
    # A slab whose node id is 10000 characters long, used as the output.
    ident = "n" * 10_000
    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        f'    "{ident}": {{ "kind": "slab", "diffuse_albedo": "$tint", "roughness": 0.5 }}\n',
        "  },\n",
        f'  "output": "{ident}"\n',
        "}\n",
    ])


def wide_fanout(path):
    # l00 is a slab; l<i> = horizontal(background = l<i-1>, foreground = l<i-1>), i = 1..40.
    # 41 nodes in the file, but instancing the DAG into a tree gives 2^40 slabs.
    levels = 40

    def nodes():
        yield '    "l00": { "kind": "slab", "diffuse_albedo": "$tint", "roughness": 0.5 },\n'
        for i in range(1, levels + 1):
            sep = "," if i < levels else ""
            yield (f'    "l{i:02d}": {{ "kind": "horizontal", "background": "l{i - 1:02d}", '
                   f'"foreground": "l{i - 1:02d}", "mix": 0.5 }}{sep}\n')

    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        *nodes(),
        "  },\n",
        f'  "output": "l{levels:02d}"\n',
        "}\n",
    ])


def many_inputs(path):
    # 100000 float inputs (5 MB): over the input-count limit (each is a uniform-block member;
    # SPIR-V caps a struct at 16383 members, so the compiler must stop long before).
    n = 100_000

    def inputs():
        for i in range(n):
            sep = "," if i < n - 1 else ""
            yield f'    "i{i:06d}": {{ "type": "float", "default": 0.5 }}{sep}\n'

    write_chunks(path, [
        '{\n  "format": "substrate-material/1",\n  "name": "m",\n  "inputs": {\n',
        *inputs(),
        "  },\n",
        '  "nodes": { "base": { "kind": "slab", "roughness": "$i000005" } },\n',
        '  "output": "base"\n',
        "}\n",
    ])


def long_cycle(path):
    # A value cycle through 19000 named nodes whose ids are 120 characters: the cycle
    # diagnostic must stay short (a full chain would be a 2.3 MB line).
    n = 19_000

    def ident(i):
        return f"v{i:06d}" + "x" * 113

    def nodes():
        for i in range(n):
            yield f'    "{ident(i)}": {{ "kind": "saturate", "x": "{ident((i + 1) % n)}" }},\n'

    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        *nodes(),
        f'    "base": {{ "kind": "slab", "diffuse_albedo": "$tint", "roughness": "{ident(0)}" }}\n',
        "  },\n",
        '  "output": "base"\n',
        "}\n",
    ])


def long_string(path):
    # A 10 MiB "description" (under the 16 MiB input-size limit): the string-length limit.
    write_chunks(path, [
        HEAD,
        '  "description": "', *repeat("d", 10 * MiB), '",\n',
        '  "nodes": { "base": { "kind": "slab", "diffuse_albedo": "$tint", "roughness": 0.5 } },\n',
        '  "output": "base"\n',
        "}\n",
    ])


def long_keys(path):
    # 60 unknown pins on one slab, each a 60000-byte key: the key-length limit; the
    # diagnostics (capped at 50 errors) must not echo the keys.
    keys = [f'"{c * 60_000}": 1, ' for c in ("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ01234567")]
    write_chunks(path, [
        HEAD,
        '  "nodes": { "base": { "kind": "slab", ', *keys, '"roughness": 0.5 } },\n',
        '  "output": "base"\n',
        "}\n",
    ])


def many_inline_nodes(path):
    # 10001 named `add` nodes, each with an inline `abs` node: 10001 named nodes (under the
    # limit) but 20002 nodes in all, so the node-count limit fires on an inline node.
    n = 10_001

    def nodes():
        yield '    "n00000": { "kind": "add", "a": "$mask", "b": { "kind": "abs", "x": 0.5 } },\n'
        for i in range(1, n):
            yield f'    "n{i:05d}": {{ "kind": "add", "a": "n{i - 1:05d}", "b": {{ "kind": "abs", "x": 0.5 }} }},\n'

    write_chunks(path, [
        HEAD,
        '  "nodes": {\n',
        *nodes(),
        '    "base": { "kind": "slab", "diffuse_albedo": "$tint", '
        f'"roughness": {{ "kind": "saturate", "x": "n{n - 1:05d}" }} }}\n',
        "  },\n",
        '  "output": "base"\n',
        "}\n",
    ])


GENERATORS = {
    "deep_array.json": deep_array,
    "deep_object.json": deep_object,
    "deep_inline_nodes.json": deep_inline_nodes,
    "many_nodes.json": many_nodes,
    "huge_string.json": huge_string,
    "big_file.json": big_file,
    "long_identifier.json": long_identifier,
    "wide_fanout.json": wide_fanout,
    "many_inputs.json": many_inputs,
    "long_cycle.json": long_cycle,
    "long_string.json": long_string,
    "long_keys.json": long_keys,
    "many_inline_nodes.json": many_inline_nodes,
}


def main(argv):
    if len(argv) != 2:
        sys.stderr.write(f"usage: {argv[0]} OUTPUT_DIR\n")
        return 2
    out = argv[1]
    os.makedirs(out, exist_ok=True)
    for name, gen in GENERATORS.items():
        gen(os.path.join(out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
