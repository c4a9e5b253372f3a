//! `nbody-bench init --external NAME`: a commented sweep config for the user's own program,
//! written from configs/templates/external.toml with the program's name in it.

use crate::cli::args::InitArgs;
use anyhow::bail;
use nbody_bench::records::config::SweepConfig;
use std::path::PathBuf;

const TEMPLATE: &str = include_str!("../../configs/templates/external.toml");
/// The program name the template is written for.
const TEMPLATE_NAME: &str = "mycode";

pub fn init(args: InitArgs) -> anyhow::Result<i32> {
    let name = args.external.as_str();
    if !nbody_bench::records::external::config::plain_name(name) {
        bail!(
            "--external `{name}`: a program's name is letters, digits, '-', '_' and '.' (it names \
             its cases and the config file)"
        );
    }
    if nbody_bench::kernels::KernelKind::ALL
        .iter()
        .any(|k| k.name() == name)
    {
        bail!("--external `{name}` is a built-in kernel's name; choose another");
    }
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("{name}.toml")));
    nbody_bench::output::check_outputs(&[("--out", out.as_path())], &[])?;
    if std::fs::symlink_metadata(&out).is_ok() {
        bail!(
            "{} exists: init never replaces a file; remove it or write elsewhere with --out FILE",
            out.display()
        );
    }
    let text = TEMPLATE.replace(TEMPLATE_NAME, name);
    // What is written is a config the sweep accepts as it is.
    SweepConfig::parse(&text, &out)?;
    nbody_bench::output::write_atomic(&out, text.as_bytes())?;
    eprintln!(
        "wrote {out}: put your source beside it as {name}.c (or edit `setup` and `command`), make \
         it print `time total SECONDS`, then\n  nbody-bench sweep --config {out} --dry-run\n  \
         nbody-bench sweep --config {out}",
        out = out.display()
    );
    Ok(0)
}
