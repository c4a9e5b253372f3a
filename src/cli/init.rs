//! `nbody-bench init --external NAME [--lang c|python] [--physics gravity|lj]`: a commented sweep
//! config for the user's own program, written from a template of configs/templates/ with the
//! program's name in it; for Python also the driver NAME.py beside it, the program the config
//! runs (direct-summation gravity, or Lennard-Jones in a periodic box).

use crate::cli::args::{InitArgs, InitLang, InitPhysics};
use anyhow::bail;
use nbody_records::config::SweepConfig;
use std::path::{Path, PathBuf};

/// The program name the templates are written for.
const TEMPLATE_NAME: &str = "mycode";

/// What `init` writes for one language: the config and, when the template has one, the program
/// that goes beside it (its file extension and text).
struct Template {
    config: &'static str,
    program: Option<(&'static str, &'static str)>,
}

impl Template {
    /// The template for `lang` and `physics`; the C template is gravity's alone.
    fn of(lang: InitLang, physics: InitPhysics) -> anyhow::Result<Template> {
        Ok(match (lang, physics) {
            (InitLang::C, InitPhysics::Gravity) => Template {
                config: include_str!("../../configs/templates/external.toml"),
                program: None,
            },
            (InitLang::C, InitPhysics::Lj) => bail!(
                "--physics lj comes with a Python driver: add --lang python (the C template \
                 is a gravity code)"
            ),
            (InitLang::Python, InitPhysics::Gravity) => Template {
                config: include_str!("../../configs/templates/external-python.toml"),
                program: Some(("py", include_str!("../../configs/templates/external.py"))),
            },
            (InitLang::Python, InitPhysics::Lj) => Template {
                config: include_str!("../../configs/templates/external-lj-python.toml"),
                program: Some(("py", include_str!("../../configs/templates/external-lj.py"))),
            },
        })
    }
}

pub fn init(args: InitArgs) -> anyhow::Result<i32> {
    let name = args.external.as_str();
    if !nbody_records::external::config::plain_name(name) {
        bail!(
            "--external `{name}`: a program's name is letters, digits, '-', '_' and '.', not \
             starting with '-' (it names its cases and the config file, and the commands that \
             name them would read it as an option)"
        );
    }
    if nbody_engine::kernels::KernelKind::ALL
        .iter()
        .any(|k| k.name() == name)
    {
        bail!("--external `{name}` is a built-in kernel's name; choose another");
    }
    let template = Template::of(args.lang, args.physics)?;
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("{name}.toml")));
    // The config runs the program as {config_dir}/NAME.EXT: it goes in the config's directory.
    let program = template.program.map(|(ext, text)| {
        let dir = out.parent().unwrap_or(Path::new(""));
        (
            dir.join(format!("{name}.{ext}")),
            text.replace(TEMPLATE_NAME, name),
        )
    });
    let mut outputs = vec![("--out", out.as_path())];
    outputs.extend(
        program
            .iter()
            .map(|(path, _)| ("the program", path.as_path())),
    );
    nbody_engine::output::check_outputs(&outputs, &[])?;
    // Both are checked before either is written: a refusal leaves nothing behind.
    for (_, path) in &outputs {
        if std::fs::symlink_metadata(path).is_ok() {
            bail!(
                "{} exists: init never replaces a file; remove it or write elsewhere with --out \
                 FILE{}",
                path.display(),
                if program.is_some() {
                    " (the program goes beside the config)"
                } else {
                    ""
                }
            );
        }
    }
    let text = template.config.replace(TEMPLATE_NAME, name);
    // What is written is a config the sweep accepts as it is.
    SweepConfig::parse(&text, &out)?;
    if let Some((path, code)) = &program {
        nbody_engine::output::write_atomic(path, code.as_bytes())?;
    }
    if let Err(e) = nbody_engine::output::write_atomic(&out, text.as_bytes()) {
        // A program without its config is half an init: take it back, so that a second try
        // does not find it in the way.
        if let Some((path, _)) = &program {
            let _ = std::fs::remove_file(path);
        }
        return Err(e.into());
    }
    next_steps(
        &out,
        name,
        program.as_ref().map(|(path, _)| path.as_path()),
        args.physics,
    );
    Ok(0)
}

/// What to do with the files just written.
fn next_steps(out: &Path, name: &str, program: Option<&Path>, physics: InitPhysics) {
    let out = super::hint::arg(out);
    let then = format!(
        "put your code's calls in its `evolve`, then\n  nbody-bench sweep --config {out} \
         --dry-run\n  nbody-bench sweep --config {out}"
    );
    match (program, physics) {
        (None, _) => eprintln!(
            "wrote {out}: put your source beside it as {name}.c (or edit `setup` and `command`), \
             make it print `time total SECONDS`, then\n  nbody-bench sweep --config {out} \
             --dry-run\n  nbody-bench sweep --config {out}"
        ),
        (Some(program), InitPhysics::Gravity) => eprintln!(
            "wrote {out} and {program}, a direct-summation program that prints `time total \
             SECONDS`: try it with\n  python3 {program} --n 200 --steps 10\n{then}",
            program = super::hint::arg(program)
        ),
        (Some(program), InitPhysics::Lj) => eprintln!(
            "wrote {out} and {program}, a Lennard-Jones program in a periodic box that prints \
             `time total SECONDS`: try it with\n  nbody-bench export --scenario lj-melt -n 4000 \
             --format lammps-data --out state.data\n  python3 {program} --initial state.data \
             --steps 2\n{then}",
            program = super::hint::arg(program)
        ),
    }
}
