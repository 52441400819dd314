//! The status lines under the plots: case and loading, the readout of the state, the
//! conditions, the last solve, and the message (or the key hint).

use super::chart::{bold, sep};
use super::colours::DIM;
use super::numbers::{fmt_duration, fmt_num, fmt_short, largest};
use crate::tui::app::{fmt_step, App, Message};
use crate::tui::stability;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Wrap};
use ratatui::Frame;

/// Case and loading; boundary conditions; the last solve; messages (wrapped).
pub(super) fn draw_status(frame: &mut Frame, area: Rect, app: &App) {
    let [a, r, b, c, d] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Min(0),
    ])
    .areas(area);
    frame.render_widget(Paragraph::new(case_line(app, a.width)), a);
    frame.render_widget(Paragraph::new(readout_line(app, r.width)), r);
    frame.render_widget(Paragraph::new(boundary_line(app)), b);
    frame.render_widget(Paragraph::new(solve_line(app)), c);
    frame.render_widget(
        Paragraph::new(message_line(app)).wrap(Wrap { trim: false }),
        d,
    );
}

/// Lines the message (or the key hint) takes at `width`, wrapped, at most 3.
pub(super) fn message_lines(app: &App, width: u16) -> u16 {
    let len = match &app.message {
        Some(Message::Error(m)) | Some(Message::Info(m)) => Line::from(m.as_str()).width(),
        None => 0,
    };
    (len.div_ceil(width.max(1) as usize) as u16).clamp(1, 3)
}

/// Status line 1: case, `n`, the load parameter and its target, the step, the activity
/// (shortened to fit `width` columns).
fn case_line(app: &App, width: u16) -> Line<'static> {
    let parameter = app.screen.state.as_ref().map_or("–".to_string(), |s| {
        format!(
            "{:.5}",
            app.shown_parameter(s.point.compression_ratio, s.point.parameter)
        )
    });
    let mut spans = vec![
        bold(app.case_label()),
        sep(),
        Span::raw(format!("n {} {}", app.screen.helices, app.model_name())),
        sep(),
        Span::raw(format!("{} ", app.symbol())),
        bold(parameter),
        Span::raw(format!(" → {}", crate::case::num(app.target()))),
        sep(),
        Span::raw(format!("Δ{} {}", app.symbol(), fmt_step(app.user_step()))),
        sep(),
    ];
    let room = (width as usize).saturating_sub(Line::from(spans.clone()).width());
    spans.push(activity(app, room));
    Line::from(spans)
}

/// What the explorer is doing: solving (what, for how long, how far), running, or idle, in
/// `room` columns: how far the solve got is given up first, then the words around the
/// cancel key, which stays.
fn activity(app: &App, room: usize) -> Span<'static> {
    let solving = |job: &str, running: bool| {
        // a step, and the natural state (whose n the line shows already), drop "solving";
        // a branch switch may be named by its critical point alone
        let what = if job.starts_with(app.symbol()) {
            job.to_string()
        } else if job.starts_with("natural state") {
            "natural state".to_string()
        } else {
            format!("solving {job}")
        };
        let short = job
            .strip_prefix("branch of critical point ")
            .map_or(what.clone(), |rest| format!("branch {rest}"));
        let progress = app
            .requests
            .progress
            .map(|p| format!(" · at {:.5} ({} steps)", p.parameter, p.steps));
        let elapsed = app
            .requests
            .elapsed
            .map(|e| format!(" {:.1} s", e.as_secs_f64()));
        let runs = if running {
            ["▶ running · ", "▶ "]
        } else {
            ["", ""]
        };
        let heads: Vec<(String, String)> = runs
            .iter()
            .flat_map(|run| [&what, &short].map(|w| (run.to_string(), w.clone())))
            .collect();
        let elapsed = elapsed.unwrap_or_default();
        // how far it got, then the time, then the words around the cancel key give way
        let mut texts: Vec<String> = Vec::new();
        if let Some(p) = &progress {
            texts.extend(
                heads
                    .iter()
                    .map(|(r, w)| format!("{r}{w}…{elapsed} · c cancels{p}")),
            );
        }
        texts.extend(
            heads
                .iter()
                .map(|(r, w)| format!("{r}{w}…{elapsed} · c cancels")),
        );
        texts.extend(heads.iter().map(|(r, w)| format!("{r}{w}… c cancels")));
        texts.push("c cancels".to_string());
        texts
            .iter()
            .find(|t| Line::from(t.as_str()).width() <= room)
            .or(texts.last())
            .cloned()
            .unwrap_or_default()
    };
    match (&app.requests.solving, app.requests.running) {
        (Some(job), running) => Span::styled(solving(job, running), Style::new().fg(Color::Yellow)),
        (None, true) => Span::styled("▶ running", Style::new().fg(Color::Yellow)),
        (None, false) => Span::styled("idle", Style::new().fg(Color::Green)),
    }
}

/// The numbers of the state on screen: h, the loads, the selected rod's bulk (s/L),
/// energy, stability, and the selected rod's tip reaction, in `width` columns: the loads
/// and the stability (unstable directions, λmin) always, the others as they fit (the rod's
/// tip reaction given up first, then h, which line 1's load parameter gives; then the labels are
/// shortened; then E and last the bulk are given up).
fn readout_line(app: &App, width: u16) -> Line<'static> {
    let full = readout_fields(app, false);
    let Some(mut fields) = full else {
        return Line::from(Span::styled("no converged state", Style::new().fg(DIM)));
    };
    let fits = |fields: &[(u8, Vec<Span<'static>>)]| {
        let line = join_fields(fields);
        (line.width() <= width as usize).then_some(line)
    };
    let drop_above = |fields: &mut Vec<(u8, Vec<Span<'static>>)>, floor: u8| {
        let worst = fields
            .iter()
            .enumerate()
            .filter(|(_, (priority, _))| *priority > floor)
            .max_by_key(|(_, (priority, _))| *priority)
            .map(|(k, _)| k);
        worst.map(|k| fields.remove(k)).is_some()
    };
    loop {
        if let Some(line) = fits(&fields) {
            return line;
        }
        if !drop_above(&mut fields, 3) {
            break;
        }
    }
    // shorter labels, then the lesser fields
    let mut fields = readout_fields(app, true).unwrap_or_default();
    fields.retain(|(priority, _)| *priority <= 3);
    loop {
        if let Some(line) = fits(&fields) {
            return line;
        }
        if !drop_above(&mut fields, 0) {
            return join_fields(&fields);
        }
    }
}

/// The fields joined by separators.
fn join_fields(fields: &[(u8, Vec<Span<'static>>)]) -> Line<'static> {
    let mut spans = Vec::new();
    for (k, (_, f)) in fields.iter().enumerate() {
        if k > 0 {
            spans.push(sep());
        }
        spans.extend(f.iter().cloned());
    }
    Line::from(spans)
}

/// The readout's fields with the priority to keep each (0 always, higher given up
/// first), with shorter labels when `short`; `None` without a converged state.
fn readout_fields(app: &App, short: bool) -> Option<Vec<(u8, Vec<Span<'static>>)>> {
    let s = app.screen.state.as_ref()?;
    let p = &s.point;
    let (dirs, lowest) = match p.stability {
        Some(st) => (
            st.unstable_directions.to_string(),
            match (st.lowest_eigenvalue, st.lowest_wavenumber) {
                (Some(l), Some(k)) => format!("{} p{k}", fmt_num(l)),
                (Some(l), None) => fmt_num(l),
                (None, _) => "–".into(),
            },
        ),
        None => ("–".into(), "–".into()),
    };
    let big = largest(&p.load);
    // (priority to keep: 0 always, higher given up first; the spans)
    let mut fields: Vec<(u8, Vec<Span<'static>>)> =
        vec![(4, vec![Span::raw(format!("h {} m", fmt_num(p.height)))])];
    // the stepped load's displacement and force, then the axial loads
    if let Some([(motion, m), (force, f)]) = p.support.pair(app.case().loading.parameter) {
        fields.push((
            0,
            vec![
                Span::raw(format!("{} {} ", short_name(m), fmt_motion(motion))),
                Span::raw(format!("{} ", short_name(f))),
                bold(fmt_num(force)),
            ],
        ));
        fields.push((
            3,
            vec![Span::raw(format!("fz/nPc {}", fmt_short(p.load[2], big)))],
        ));
    } else {
        fields.push((
            0,
            vec![
                Span::raw(format!(
                    "fx {} fy {} fz/nPc ",
                    fmt_short(p.load[0], big),
                    fmt_short(p.load[1], big)
                )),
                bold(fmt_short(p.load[2], big)),
            ],
        ));
    }
    if let Some(b) = s.bulk.rods.get(app.view.selected_rod) {
        fields.push((
            2,
            vec![Span::raw(format!(
                "bulk {:.2}–{:.2}",
                b.start_over_l(),
                b.end_over_l()
            ))],
        ));
    }
    fields.push((3, vec![Span::raw(format!("E {} J", fmt_num(p.energy)))]));
    let unstable = if short { "unst." } else { "unstable" };
    fields.push((
        0,
        vec![Span::raw(format!("{unstable} {dirs} λmin {lowest}"))],
    ));
    if let Some(r) = p.reactions.get(app.view.selected_rod) {
        let f = r.tip.force;
        let big = largest(&f);
        fields.push((
            5,
            vec![Span::raw(format!(
                "rod {} tip F ({}, {}, {}) N",
                r.rod,
                fmt_short(f[0], big),
                fmt_short(f[1], big),
                fmt_short(f[2], big)
            ))],
        ));
    }
    Some(fields)
}

/// Status line 2: the conditions in force, the mesh an accuracy target chose, and the
/// conditions asked for when they are not in force yet.
fn boundary_line(app: &App) -> Line<'static> {
    let in_force = app
        .screen
        .state
        .as_ref()
        .map_or(app.screen.boundary, |s| s.boundary);
    let mut line = vec![
        Span::raw(format!("base {}", in_force.base.label())),
        sep(),
        Span::raw(format!("tip {}", in_force.tip.label())),
        sep(),
        Span::raw(format!("joints {}", in_force.joints_label())),
    ];
    if let Some(m) = &app.screen.mesh {
        // the mesh an accuracy target chose, with the error estimated for it
        line.push(sep());
        line.push(Span::raw(format!(
            "mesh {} {}, err {:.0e}",
            m.elements,
            m.order.name(),
            m.estimated_error
        )));
    }
    // the elastic hypotheses, when they are not the thesis's
    let case = app.case();
    let hypotheses = match (case.rod.stress_free, case.rod.energy) {
        (_, crate::model::elasticity::Energy::Sadowsky(_)) => Some("Sadowsky ribbons"),
        (crate::model::elasticity::StressFree::Straight, _) => Some("rods straight at rest"),
        _ => None,
    };
    if let Some(h) = hypotheses {
        line.push(sep());
        line.push(Span::raw(h));
    }
    if case.discretisation.reference == crate::model::elasticity::Reference::Continuum {
        line.push(sep());
        line.push(Span::raw("continuum κ*"));
    }
    // an imperfect case: its flaw
    if let Some(imp) = &case.imperfection {
        line.push(sep());
        line.push(Span::styled(
            format!(
                "flaw {}, δ {} L",
                imp.shape.name(),
                crate::case::num(imp.amplitude)
            ),
            Style::new().fg(Color::Magenta),
        ));
    }
    if in_force != app.screen.boundary {
        line.push(sep());
        line.push(Span::styled(
            format!("asked: {}", app.screen.boundary.label()),
            Style::new().fg(Color::Yellow),
        ));
    }
    Line::from(line)
}

/// Status line 3: stability of the state on screen and how its solve went.
fn solve_line(app: &App) -> Line<'static> {
    let unstable = app.stability();
    let stability_style = match unstable {
        Some(true) => Style::new()
            .fg(Color::LightRed)
            .add_modifier(Modifier::BOLD),
        _ => Style::new(),
    };
    match app.screen.state.as_ref() {
        // stability first: on a narrow screen the line is cut from the right
        Some(s) => Line::from(vec![
            Span::raw("stability "),
            Span::styled(stability::label(unstable), stability_style),
            sep(),
            Span::raw(format!(
                "Newton {} it, |R| {:.1e}",
                s.point.iterations, s.point.residual
            )),
            sep(),
            Span::raw(format!("solve {}", fmt_duration(s.time))),
            sep(),
            Span::raw(format!("inner step {}", fmt_num(s.step_length))),
        ]),
        None => Line::from(vec![Span::raw("stability "), Span::raw("n/a")]),
    }
}

/// The message for the user, or the key hint.
fn message_line(app: &App) -> Line<'static> {
    match &app.message {
        Some(Message::Error(m)) => {
            Line::from(Span::styled(m.clone(), Style::new().fg(Color::LightRed)))
        }
        Some(Message::Info(m)) => {
            Line::from(Span::styled(m.clone(), Style::new().fg(Color::Green)))
        }
        None => Line::from(Span::styled(
            format!(
                "←→ step  ↑↓ rod  space run  +- Δ{}  e export  ? help (all keys)  q quit",
                app.symbol()
            ),
            Style::new().fg(DIM),
        )),
    }
}

/// A column name such as `T (N m)` as the readout prints it: `T/N m`.
fn short_name(name: &str) -> String {
    match name.split_once(" (") {
        Some((symbol, unit)) => format!("{symbol}/{}", unit.trim_end_matches(')')),
        None => name.to_string(),
    }
}

/// A displacement to 5 significant figures (a radius moves in its fourth digit).
fn fmt_motion(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return fmt_num(v);
    }
    let decimals = (4 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.decimals$}")
}
