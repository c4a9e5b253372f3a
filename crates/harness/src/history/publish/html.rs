//! The page's HTML: a header saying what the charts show, each machine class with its latest
//! gate run, a table of every step found, REPORT.md's figures, then one section per case with
//! one chart per class side by side. The inline script only adds a filter box over the case
//! keys and a tooltip; without it the page reads the same (the points carry `<title>`s).

use super::chart::{self, percent, value};
use super::{CaseView, Chart, ClassView, Page, esc, short};
use crate::gate::Verdict;
use crate::history::series::Metric;
use crate::history::verdicts::GateRun;
use nbody_engine::output::neutral::url;
use std::fmt::Write;

const STYLE: &str = r#"
:root { --ink: #1f2328; --muted: #59636e; --line: #d1d9e0; --band: #9ec5fe; --median: #0b5cad;
  --slower: #b42318; --faster: #1a7f37; --bg: #ffffff; --panel: #f6f8fa; }
* { box-sizing: border-box; }
body { margin: 0 auto; max-width: 1320px; padding: 16px 24px 48px; color: var(--ink); background: var(--bg);
  font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
h1 { font-size: 24px; margin: 8px 0 4px; }
h2 { font-size: 18px; margin: 28px 0 8px; border-bottom: 1px solid var(--line); padding-bottom: 4px; }
h3 { font-size: 15px; margin: 12px 0 4px; }
code, .key { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; font-size: 13px; }
p.lead { color: var(--muted); max-width: 100ch; margin: 4px 0; }
table { border-collapse: collapse; margin: 6px 0 10px; }
th, td { border-bottom: 1px solid var(--line); padding: 3px 10px 3px 0; text-align: left; vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.regressed, .slower { color: var(--slower); font-weight: 600; }
.improved, .faster { color: var(--faster); font-weight: 600; }
.unchanged { color: var(--muted); }
.classes { display: grid; grid-template-columns: repeat(auto-fit, minmax(420px, 1fr)); gap: 12px; }
.class { background: var(--panel); border: 1px solid var(--line); border-radius: 6px; padding: 8px 12px; }
#filter-box { margin: 12px 0; }
#filter { font: inherit; padding: 4px 8px; width: 28em; max-width: 100%; }
section.case { margin: 18px 0 6px; }
section.case h2 { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; font-size: 15px;
  word-break: break-all; }
.charts { display: grid; grid-template-columns: repeat(auto-fill, minmax(600px, 1fr)); gap: 12px; }
figure { margin: 0; border: 1px solid var(--line); border-radius: 6px; padding: 6px 8px; background: var(--bg); }
figcaption { font-size: 13px; margin-bottom: 2px; }
figcaption .verdict { margin-left: 6px; }
ul.steps { margin: 2px 0 0; padding-left: 18px; font-size: 13px; }
p.absent { color: var(--muted); font-style: italic; }
svg.chart { display: block; width: 100%; height: auto; max-width: 600px; }
svg text { font: 11px system-ui, -apple-system, "Segoe UI", Roboto, Arial, sans-serif; fill: var(--ink); }
svg text.commit { font: 10px ui-monospace, Menlo, Consolas, monospace; fill: var(--muted); }
svg text.tick { fill: var(--muted); }
svg text.axis { font-weight: 600; }
svg .frame { fill: none; stroke: var(--line); }
svg .grid { stroke: #eaeef2; }
svg .band { fill: var(--band); fill-opacity: 0.55; stroke: none; }
svg .median { fill: none; stroke: var(--median); stroke-width: 1.6; }
svg circle.point { fill: var(--median); stroke: #fff; stroke-width: 0.8; }
svg circle.point:hover { r: 5; }
svg .level { stroke: var(--ink); stroke-opacity: 0.45; stroke-width: 1; stroke-dasharray: 6 3; }
svg g.change line, svg .change-key { stroke: var(--slower); stroke-width: 1.4; stroke-dasharray: 4 3; }
svg g.change.faster line { stroke: var(--faster); }
svg g.change text { font-weight: 600; fill: var(--slower); }
svg g.change.faster text { fill: var(--faster); }
.tip { position: fixed; pointer-events: none; background: #1f2328; color: #fff; padding: 4px 8px; border-radius: 4px;
  font-size: 12px; white-space: pre; z-index: 10; }
ul.figures { columns: 2 520px; font-size: 13px; }
ul.figures code { color: var(--muted); font-size: 11px; }
footer { margin-top: 32px; color: var(--muted); font-size: 12px; }
"#;

/// The script: a filter over case keys and a tooltip on the points. It marks the document
/// (`data-script="ran"`) so that a test can tell it ran.
const SCRIPT: &str = r#"
(function () {
  var box = document.getElementById('filter-box');
  var input = document.getElementById('filter');
  var shown = document.getElementById('shown');
  var cases = Array.prototype.slice.call(document.querySelectorAll('section.case'));
  function apply() {
    var q = input.value.trim().toLowerCase(), n = 0;
    cases.forEach(function (s) {
      var hit = !q || s.getAttribute('data-case').toLowerCase().indexOf(q) >= 0;
      s.hidden = !hit;
      if (hit) { n += 1; }
    });
    shown.textContent = n + ' of ' + cases.length + ' cases shown';
  }
  box.hidden = false;
  input.addEventListener('input', apply);
  apply();
  var tip = document.createElement('div');
  tip.className = 'tip';
  tip.hidden = true;
  document.body.appendChild(tip);
  document.querySelectorAll('circle.point[data-commit]').forEach(function (c) {
    c.addEventListener('mouseenter', function (e) {
      tip.textContent = 'commit ' + c.getAttribute('data-commit') + '\n' + c.getAttribute('data-date') +
        '\nmedian ' + c.getAttribute('data-value') + '\n95% interval ' + c.getAttribute('data-ci');
      tip.hidden = false;
      tip.style.left = (e.clientX + 12) + 'px';
      tip.style.top = (e.clientY + 12) + 'px';
    });
    c.addEventListener('mouseleave', function () { tip.hidden = true; });
  });
  document.documentElement.setAttribute('data-script', 'ran');
})();
"#;

/// The whole page.
pub fn html(page: &Page) -> String {
    let mut o = String::new();
    o.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    o.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    o.push_str("<title>nbody-bench: performance history</title>\n<style>");
    o.push_str(STYLE);
    o.push_str("</style>\n</head>\n<body>\n");
    header(&mut o, page);
    o.push_str("<h2 id=\"classes\">Machine classes and their latest gate run</h2>\n<div class=\"classes\">\n");
    for c in &page.classes {
        class(&mut o, c);
    }
    o.push_str("</div>\n");
    changes(&mut o, page);
    figures(&mut o, page);
    o.push_str("<h2 id=\"cases\">Cases</h2>\n<p id=\"filter-box\" hidden><label>Filter cases: <input id=\"filter\" type=\"search\" placeholder=\"part of a case key, e.g. galaxy/symmetric\"></label> <span id=\"shown\"></span></p>\n");
    for c in &page.cases {
        case(&mut o, c);
    }
    o.push_str(
        "<footer>Written by <code>nbody-bench publish</code> from the history files; \
        regenerate it rather than editing it.</footer>\n<script>",
    );
    o.push_str(SCRIPT);
    o.push_str("</script>\n</body>\n</html>\n");
    o
}

fn header(o: &mut String, page: &Page) {
    let records: usize = page.classes.iter().map(|c| c.records).sum();
    let _ = writeln!(
        o,
        "<h1>Performance history</h1>\n<p class=\"lead\">{} cases on {} machine class{}, \
         {records} records; newest measurement {}.</p>",
        page.cases.len(),
        page.classes.len(),
        if page.classes.len() == 1 { "" } else { "es" },
        esc(page.newest().unwrap_or("unknown")),
    );
    o.push_str(
        "<p class=\"lead\">Each chart is one case on one machine class: one point per commit, \
         oldest on the left, the median time per step with its 95% interval (over the \
         reference workload timed before each sample where every record has it, else in \
         seconds). Records of builds with uncommitted changes are left out. A dashed vertical \
         line marks a step found by the history's change-point detector, labelled with the \
         last commit of the old level, the first of the new, and the change in the level \
         (red: slower, green: faster).</p>\n",
    );
}

fn verdict_cell(v: Verdict) -> String {
    format!("<span class=\"{0}\">{0}</span>", v.name())
}

fn interval(ci: [f64; 2]) -> String {
    format!("[{:.3}, {:.3}]", ci[0], ci[1])
}

/// `base → current` of a gate run, each marked when it had uncommitted changes.
pub(super) fn gate_commits(g: &GateRun) -> String {
    let mark = |dirty: bool| if dirty { " (uncommitted changes)" } else { "" };
    format!(
        "{}{} → {}{}",
        short(&g.base),
        mark(g.base_dirty),
        short(&g.current),
        mark(g.current_dirty)
    )
}

fn class(o: &mut String, c: &ClassView) {
    let _ = writeln!(
        o,
        "<div class=\"class\" data-class=\"{cl}\"><h3>{cl}</h3>\n<p>{} records, {} commits, \
         newest measurement {}.</p>",
        c.records,
        c.commits,
        esc(c.newest.as_deref().unwrap_or("unknown")),
        cl = esc(&c.class),
    );
    let Some(g) = &c.latest_gate else {
        o.push_str("<p>No gate run recorded for this class.</p></div>\n");
        return;
    };
    let count = |v: Verdict| g.cases.iter().filter(|c| c.verdict == v).count();
    let _ = writeln!(
        o,
        "<p class=\"gate\" data-base=\"{}\" data-current=\"{}\">Latest gate run, {}: \
         <code>{}</code>, threshold ±{}%, judged on the {} ratio: \
         <span class=\"regressed\">{} regressed</span>, <span class=\"improved\">{} improved\
         </span>, {} unchanged{}.</p>",
        esc(short(&g.base)),
        esc(short(&g.current)),
        esc(&g.measured),
        esc(&gate_commits(g)),
        100.0 * g.threshold,
        match g.judged_on {
            crate::gate::Judged::Raw => "raw",
            crate::gate::Judged::Normalized => "normalised",
            crate::gate::Judged::Both => "normalised and the raw",
        },
        count(Verdict::Regressed),
        count(Verdict::Improved),
        count(Verdict::Unchanged),
        if g.missing.is_empty() {
            String::new()
        } else {
            format!(", {} missing", g.missing.len())
        },
    );
    if let Some(a) = &g.acceptance {
        // A regression let into the baseline on purpose is shown as such, with why.
        let keys: Vec<String> = a.cases.iter().map(|c| esc(&c.key)).collect();
        let _ = writeln!(
            o,
            "<p class=\"accepted\">Accepted into the baseline when it was saved ({}): <code>{}\
             </code>, because: {}</p>",
            esc(&a.accepted),
            keys.join("</code>, <code>"),
            esc(&a.reason)
        );
    }
    let _ = writeln!(
        o,
        "<details><summary>Every case of that run (ratio current / base)</summary>\n<table \
         class=\"verdicts\"><tr><th>case</th><th>verdict</th><th>ratio</th><th>95% interval</th></tr>"
    );
    for v in &g.cases {
        let _ = writeln!(
            o,
            "<tr data-case=\"{k}\"><td class=\"key\">{k}</td><td>{}</td><td class=\"num\">{:.3}</td>\
             <td class=\"num\">{}</td></tr>",
            verdict_cell(v.verdict),
            v.ratio,
            interval(v.ci95),
            k = esc(&v.key),
        );
    }
    o.push_str("</table></details></div>\n");
}

fn changes(o: &mut String, page: &Page) {
    o.push_str("<h2 id=\"changes\">Steps found</h2>\n");
    let all: Vec<&Chart> = page.charts().filter(|c| !c.steps.is_empty()).collect();
    if all.is_empty() {
        o.push_str("<p>No step in any series.</p>\n");
        drifts(o, page);
        return;
    }
    o.push_str(
        "<table class=\"changes\"><tr><th>case</th><th>class</th><th>between</th>\
         <th>level before → after</th><th>change</th><th>95% interval</th></tr>\n",
    );
    for c in all {
        let s = &c.series;
        for st in &c.steps {
            let t = StepText::of(s.metric, st);
            let _ = writeln!(
                o,
                "<tr><td class=\"key\">{}</td><td>{}</td><td><code>{}..{}</code></td><td>{} → {}</td>\
                 <td class=\"num {}\">{}</td><td class=\"num\">[{}, {}]</td></tr>",
                esc(&s.case),
                esc(&s.class),
                t.from,
                t.to,
                t.before,
                t.after,
                t.way,
                t.size,
                t.low,
                t.high,
            );
        }
    }
    o.push_str("</table>\n");
    drifts(o, page);
}

/// The drifts of every series, when any has one: a page of a history without drifts is what
/// it was before drifts were looked for.
fn drifts(o: &mut String, page: &Page) {
    let all: Vec<&Chart> = page.charts().filter(|c| !c.drifts.is_empty()).collect();
    if all.is_empty() {
        return;
    }
    o.push_str(
        "<h2 id=\"drifts\">Drifts found</h2>\n<table class=\"changes\"><tr><th>case</th>\
         <th>class</th><th>from..to</th><th>change</th><th>95% interval</th><th>per commit</th>\
         </tr>\n",
    );
    for c in all {
        let s = &c.series;
        for d in &c.drifts {
            let _ = writeln!(
                o,
                "<tr><td class=\"key\">{}</td><td>{}</td><td><code>{}..{}</code></td>\
                 <td class=\"num {}\">{}</td><td class=\"num\">[{}, {}]</td>\
                 <td class=\"num\">{:+.2}%</td></tr>",
                esc(&s.case),
                esc(&s.class),
                esc(short(&d.range[0])),
                esc(short(&d.range[1])),
                if d.ratio > 1.0 { "slower" } else { "faster" },
                percent(d.ratio),
                percent(d.ratio_ci95[0]),
                percent(d.ratio_ci95[1]),
                100.0 * (d.per_commit - 1.0),
            );
        }
    }
    o.push_str("</table>\n");
}

fn figures(o: &mut String, page: &Page) {
    if page.figures.is_empty() {
        return;
    }
    o.push_str("<h2 id=\"figures\">Figures of REPORT.md</h2>\n<ul class=\"figures\">\n");
    for f in &page.figures {
        // The link comes from REPORT.md's text: a link that is not to a document (a
        // `javascript:` URL) is shown, not followed.
        let title = match url::href(&f.href) {
            Some(href) => format!("<a href=\"{}\">{}</a>", esc(href), esc(&f.title)),
            None => esc(&f.title),
        };
        let _ = writeln!(o, "<li>{title} <code>{}</code></li>", esc(&f.path));
    }
    o.push_str("</ul>\n");
}

fn case(o: &mut String, c: &CaseView) {
    let _ = writeln!(
        o,
        "<section class=\"case\" data-case=\"{k}\">\n<h2>{k}</h2>\n<div class=\"charts\">",
        k = esc(&c.key)
    );
    for ch in &c.charts {
        let s = &ch.series;
        let _ = write!(
            o,
            "<figure data-class=\"{cl}\"><figcaption><strong>{cl}</strong> · config {} · {} commits{}",
            esc(&s.config),
            s.points.len(),
            match s.metric {
                Metric::Normalized => "",
                Metric::Seconds => " · in seconds (not every record has the reference timing)",
            },
            cl = esc(&s.class),
        );
        if let Some(v) = &ch.verdict {
            let _ = write!(
                o,
                "<span class=\"verdict\">· latest gate: {} {:.3} {}</span>",
                verdict_cell(v.verdict),
                v.ratio,
                interval(v.ci95)
            );
        }
        o.push_str("</figcaption>\n");
        o.push_str(&chart::svg(ch));
        o.push('\n');
        if ch.steps.is_empty() && ch.drifts.is_empty() {
            o.push_str("<ul class=\"steps\"><li>no step</li></ul>\n");
        } else {
            o.push_str("<ul class=\"steps\">");
            for st in &ch.steps {
                let t = StepText::of(s.metric, st);
                let _ = write!(
                    o,
                    "<li>step between <code>{}</code> and <code>{}</code>: {} → {} \
                     (<span class=\"{}\">{}</span>, 95% interval [{}, {}])</li>",
                    t.from, t.to, t.before, t.after, t.way, t.size, t.low, t.high,
                );
            }
            for d in &ch.drifts {
                let [a, b] = d
                    .range
                    .each_ref()
                    .map(|c| format!("<code>{}</code>", esc(short(c))));
                let _ = write!(o, "<li>{}</li>", d.text(&a, &b));
            }
            o.push_str("</ul>\n");
        }
        o.push_str("</figure>\n");
    }
    for class in &c.absent {
        let _ = writeln!(
            o,
            "<figure data-class=\"{0}\"><figcaption><strong>{0}</strong></figcaption><p \
             class=\"absent\">No record of this case on this class.</p></figure>",
            esc(class)
        );
    }
    o.push_str("</div>\n</section>\n");
}

/// A step's parts as the page writes them (escaped): the commits between which it happened,
/// the levels, its direction as a CSS class, its size and interval.
struct StepText {
    from: String,
    to: String,
    before: String,
    after: String,
    way: &'static str,
    size: String,
    low: String,
    high: String,
}

impl StepText {
    fn of(metric: Metric, st: &crate::history::steps::Step) -> StepText {
        StepText {
            from: esc(short(&st.between[0])),
            to: esc(short(&st.between[1])),
            before: esc(&value(metric, st.before)),
            after: esc(&value(metric, st.after)),
            way: if st.ratio > 1.0 { "slower" } else { "faster" },
            size: percent(st.ratio),
            low: percent(st.ratio_ci95[0]),
            high: percent(st.ratio_ci95[1]),
        }
    }
}
