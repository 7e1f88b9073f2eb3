"""substrate_material: one substrate-material/1 file compiled by substratec.

The action runs `substratec compile @PARAMS` (PARAMS: the material and `-o DIR`),
which Bazel turns into a WorkRequest for a persistent worker started as
`substratec compile --persistent_worker` (docs/scenes.md, "Persistent worker").
Its output is a directory: the files' names come from the material's `name`.
"""

def _substrate_material_impl(ctx):
    out = ctx.actions.declare_directory(ctx.label.name)
    args = ctx.actions.args()
    args.add(ctx.file.src.path)
    args.add("-o", out.path)
    args.add_all(ctx.attr.options)
    args.use_param_file("@%s", use_always = True)
    args.set_param_file_format("multiline")
    ctx.actions.run(
        executable = ctx.executable._substratec,
        arguments = ["compile", args],
        inputs = [ctx.file.src],
        outputs = [out],
        mnemonic = "SubstrateCompile",
        progress_message = "Compiling material %s" % ctx.file.src.short_path,
        execution_requirements = {
            "supports-workers": "1",
            "supports-multiplex-workers": "1",
            "requires-worker-protocol": "json",
        },
    )
    return [DefaultInfo(files = depset([out]))]

substrate_material = rule(
    implementation = _substrate_material_impl,
    attrs = {
        "src": attr.label(allow_single_file = [".json"], mandatory = True),
        "options": attr.string_list(doc = "More `substratec compile` options, e.g. [\"--target\", \"glsl\"]."),
        "_substratec": attr.label(
            default = "//tools:substratec",
            executable = True,
            cfg = "exec",
            allow_single_file = True,
        ),
    },
)
