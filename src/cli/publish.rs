//! `nbody-bench publish`: the performance history as one self-contained HTML page, or as a
//! Markdown summary for a pull-request comment (`--markdown`). The page and the summary are
//! the library's (`nbody_harness::history::publish`); this parses, calls it and prints.

use super::history::DEFAULT_DIR;
use anyhow::Context;
use clap::Args;
use nbody_harness::history::publish::{self, markdown};
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  nbody-bench publish                       # results/history/page/index.html\n  \
    nbody-bench publish --out /tmp/page       # /tmp/page/index.html\n  \
    nbody-bench publish --markdown            # the changes since the merge base with origin/main\n  \
    nbody-bench publish --markdown --base HEAD~5\n\n\
    The page holds everything inline (SVG charts, styles, a small script for a filter box and \
    tooltips; no network): per case, one chart per machine class side by side, the median per \
    commit with its 95% interval, the steps the `history` command finds marked between their \
    two commits with their size, each class's latest gate verdicts (from <class>.gate.jsonl \
    beside the history), and links to the figures REPORT.md shows. The same history gives the \
    same bytes: the page's only date is its newest measurement's."
)]
pub struct PublishArgs {
    /// The folder of history files: every <class>.jsonl in it, and the <class>.gate.jsonl
    /// beside each.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_DIR)]
    pub dir: PathBuf,
    /// Write the page as DIR/index.html (created as needed, replaced atomically) [default:
    /// <--dir>/page].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The report whose figures the page links (those that exist, by paths relative to the
    /// page's folder; a link that is not http, https, mailto or a relative path is shown as
    /// text). A regular file: a pipe or a device is refused.
    #[arg(long, value_name = "FILE", default_value = "REPORT.md")]
    pub report: PathBuf,
    /// Print a Markdown summary for a pull-request comment instead of writing the page: per
    /// machine class, the steps found since the base commit with their sizes and intervals,
    /// and the latest gate run's regressions and improvements.
    #[arg(long)]
    pub markdown: bool,
    /// With --markdown: count the changes after this commit [default: the merge base of HEAD
    /// and origin/main, else HEAD's first parent; without git, every step is listed].
    #[arg(long, value_name = "REV", requires = "markdown")]
    pub base: Option<String>,
}

pub fn publish(args: PublishArgs) -> anyhow::Result<i32> {
    if args.markdown {
        let loaded = publish::load(&args.dir)?;
        warn(&loaded.warnings);
        let page = publish::page(&loaded, Vec::new())?;
        let base = markdown::resolve(Path::new("."), args.base.as_deref(), &page)
            .map_err(anyhow::Error::msg)?;
        out!("{}", markdown::summary(&page, &base));
        return Ok(0);
    }
    let out = args.out.clone().unwrap_or_else(|| args.dir.join("page"));
    // The history first: a missing one is the error to report, not the folder for the page.
    publish::load(&args.dir)?;
    nbody_engine::output::create_dir_all(&out).with_context(|| {
        format!(
            "cannot create {}: choose a folder you can write to with --out",
            out.display()
        )
    })?;
    let (page, warnings) = publish::build(&args.dir, &args.report, &out)?;
    warn(&warnings);
    let path = publish::write(&page, &out)?;
    let steps: usize = page.charts().map(|c| c.steps.len()).sum();
    eprintln!(
        "publish: {} cases on {} machine classes, {steps} steps, {} figures linked",
        page.cases.len(),
        page.classes.len(),
        page.figures.len()
    );
    outln!("{}", path.display());
    Ok(0)
}

/// The lines left out of the history files; they quote those files, so their control
/// characters are shown escaped.
fn warn(warnings: &[String]) {
    for w in warnings {
        eprintln!(
            "warning: {}",
            nbody_engine::output::neutral::control::visible(w)
        );
    }
}
