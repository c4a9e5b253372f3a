//! `reference` (hidden): prints the generated pages of `docs/reference/`, so that they come from
//! the code and cannot drift from it. `cli` renders the help of every subcommand from the clap
//! definitions in [`args`](crate::cli::args); `config` lists every key of a sweep config from
//! the doc comments of the config's fields (`nbody_records::config_reference`). The suite
//! (`tests/suite/docs.rs`) compares both with the committed pages.

use crate::cli::args::{Cli, ReferenceArgs, ReferencePage};
use clap::CommandFactory;

/// Width the help is laid out for, whatever the terminal: the page is the same everywhere.
const WIDTH: usize = 100;

/// How the pages are regenerated, said at the top of each.
const REGENERATE: &str = "Generated from the code by `nbody-bench reference PAGE`; do not edit. \
    `NBODY_BENCH_UPDATE_DOCS=1 cargo test --test suite docs` rewrites it, and the same tests fail \
    while it is stale.";

pub fn reference(args: ReferenceArgs) -> anyhow::Result<i32> {
    let page = match args.page {
        ReferencePage::Cli => cli_page(),
        ReferencePage::Config => config_page()?,
    };
    out!("{page}");
    Ok(0)
}

/// The long help of the command and of every visible subcommand, as Markdown.
pub fn cli_page() -> String {
    let mut root = Cli::command()
        .term_width(WIDTH)
        .max_term_width(WIDTH)
        .color(clap::ColorChoice::Never);
    root.build();
    let mut page = String::from("# Command-line reference\n\n");
    page.push_str(&REGENERATE.replace("PAGE", "cli"));
    page.push_str(
        "\n\nEvery subcommand's `--help`. The [README](../../README.md) has one line per \
         subcommand; the [tutorial](../tutorial.md) uses them in order.\n\n",
    );
    page.push_str("## Subcommands\n\n");
    let names: Vec<String> = root
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
        .map(|s| s.get_name().to_string())
        .collect();
    for name in &names {
        page.push_str(&format!("- [`{name}`](#nbody-bench-{name})\n"));
    }
    page.push_str("\n## nbody-bench\n\n");
    push_help(&mut page, &mut root);
    for sub in root
        .get_subcommands_mut()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
    {
        page.push_str(&format!("\n## nbody-bench {}\n\n", sub.get_name()));
        push_help(&mut page, sub);
    }
    page
}

fn push_help(page: &mut String, cmd: &mut clap::Command) {
    let help = cmd.render_long_help().to_string();
    page.push_str("```text\n");
    for line in help.trim_end().lines() {
        page.push_str(line.trim_end());
        page.push('\n');
    }
    page.push_str("```\n");
}

/// The sweep config's keys, each from its field's doc comment (`nbody_records::config_reference`).
pub fn config_page() -> anyhow::Result<String> {
    Ok(nbody_records::config_reference::page(
        &REGENERATE.replace("PAGE", "config"),
    )?)
}
