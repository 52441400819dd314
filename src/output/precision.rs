//! The work-precision study as text: the table `spira precision` prints, the header lines,
//! `precision.csv` and the log-log chart `precision.svg`; and the lines that say how a mesh
//! was chosen for an accuracy. The study itself ([`crate::study`]) only computes.

use super::chart::{self, Panel, Series};
use super::csv::{format, table};
use crate::discretisation::shape::Order;
use crate::study::{Measure, MeshChoice, Reference, Study, MAX_ELEMENTS, ORDERS};
use serde::Serialize;
use std::fmt::Write as _;

/// A study as tables, lines and charts.
pub trait StudyReport {
    /// How the times were taken.
    fn timing(&self) -> String;
    /// The table `spira precision` prints: one line per mesh, its wall time (ms), the error
    /// of each measure and the order observed from the previous mesh of its element order.
    fn table(&self) -> String;
    /// Header lines (without `#`) of the CSV and the report.
    fn header(&self) -> Vec<String>;
    /// `precision.csv`: the header as `#` lines, then one row per rung.
    fn csv(&self) -> String;
    /// Chart points of one order and measure, coarse to fine: `x` the time (s), `y` the
    /// error, labelled by elements per rod, hollow where the error is the reference's own
    /// estimate. A zero error has no place on a log scale and is left out.
    fn points(&self, order: Order, m: Measure) -> Vec<chart::Point>;
    /// The work-precision chart: one panel per measure that has values, log error against
    /// log time, one line per element order, one point per mesh (labelled by its elements
    /// per rod).
    fn svg(&self) -> Result<String, chart::DrawError>;
    /// [`StudyReport::svg`] with `command` (the command line that made it) as the last
    /// caption line.
    fn svg_for(&self, command: &str) -> Result<String, chart::DrawError>;
}

/// Whether `name` is a file a precision study writes.
pub fn is_precision_file(name: &str) -> bool {
    matches!(name, "precision.csv" | "precision.svg")
}

/// A row of `precision.csv`: one mesh of the ladder.
#[derive(Serialize, Default)]
struct RungRow {
    /// Element order, `linear` or `quadratic`.
    discretisation: &'static str,
    elements_asked: usize,
    /// Elements per rod of the mesh.
    elements: usize,
    /// Unknowns of the system, multipliers included (empty when the solve failed).
    unknowns: Option<usize>,
    /// Best wall time of the whole solve (s).
    #[serde(serialize_with = "format::e6")]
    time_s: f64,
    #[serde(serialize_with = "format::opt_e12")]
    response: Option<f64>,
    /// Load parameter of the first critical point.
    #[serde(serialize_with = "format::opt_e6")]
    critical: Option<f64>,
    /// Relative errors against the reference.
    #[serde(serialize_with = "format::opt_e6")]
    error_response: Option<f64>,
    #[serde(serialize_with = "format::opt_e6")]
    error_curvature: Option<f64>,
    #[serde(serialize_with = "format::opt_e6")]
    error_critical: Option<f64>,
    /// Orders observed in `h` from the previous mesh of the same element order.
    #[serde(serialize_with = "format::opt_e6")]
    order_response: Option<f64>,
    #[serde(serialize_with = "format::opt_e6")]
    order_curvature: Option<f64>,
    #[serde(serialize_with = "format::opt_e6")]
    order_critical: Option<f64>,
    /// 1 where the orders are the reference's by construction.
    by_construction: u8,
    /// Why the solve failed (empty when it did not).
    failure: Option<String>,
}

impl StudyReport for Study {
    fn timing(&self) -> String {
        match self.repeats {
            0 => "one run (no warm-up)".to_string(),
            1 => "one run after a warm-up".to_string(),
            k => format!("best of {k} runs after a warm-up"),
        }
    }

    fn table(&self) -> String {
        let mut s = String::new();
        let measures: Vec<Measure> = Measure::ALL
            .into_iter()
            .filter(|&m| m == Measure::Response || self.has(m))
            .collect();
        let _ = write!(
            s,
            "{:<10} {:>8} {:>9} {:>11}",
            "elements", "per rod", "unknowns", "time (ms)"
        );
        for m in &measures {
            let _ = write!(
                s,
                " {:>11} {:>6}",
                format!("{} error", short_name(*m)),
                "order"
            );
        }
        s.push('\n');
        for r in &self.rungs {
            let _ = write!(
                s,
                "{:<10} {:>8} {:>9} {:>11}",
                r.rung.order.name(),
                r.elements(),
                r.values
                    .as_ref()
                    .map_or("-".into(), |v| v.unknowns.to_string()),
                format!("{:.2}", r.time.as_secs_f64() * 1e3)
            );
            match &r.values {
                Err(e) => {
                    let _ = write!(s, " failed: {e}");
                }
                Ok(_) => {
                    for m in &measures {
                        let err = r.error(*m).map_or("-".into(), |e| format!("{e:.3e}"));
                        let ord = match r.observed(*m) {
                            Some(o) if r.by_construction => format!("({o:.2})"),
                            Some(o) => format!("{o:.2}"),
                            None => "-".into(),
                        };
                        let _ = write!(s, " {err:>11} {ord:>6}");
                    }
                }
            }
            s.push('\n');
        }
        s
    }

    fn header(&self) -> Vec<String> {
        let mut lines = vec![
            format!("work-precision study, case {}: {}", self.name, self.description),
            format!("reference: {}", describe_reference(&self.reference)),
            format!(
                "response: {} = {:.10e} (reference); time of the whole solve: {}",
                self.response_label,
                self.reference_values.response,
                self.timing()
            ),
            "errors relative: response |Q - Q_ref|/|Q_ref|; curvature max |k - k_ref| over rods, coarsest-mesh vertices and k1,k2,Omega / max |k_ref|; critical: first critical load parameter".to_string(),
        ];
        if let Reference::Richardson { order, check, .. } = &self.reference {
            let parts: Vec<String> = Measure::ALL
                .iter()
                .zip(check)
                .filter_map(|(m, c)| c.map(|c| format!("{} {c:.2}", m.name())))
                .collect();
            if !parts.is_empty() {
                lines.push(format!(
                    "check of the reference: orders observed over the three finest {} meshes (independent of the reference): {}",
                    order.name(),
                    parts.join(", ")
                ));
            }
            lines.push(format!(
                "orders in parentheses: the finest {} pair defines the reference, so its order equals the theoretical one by construction",
                order.name()
            ));
        }
        let theory: Vec<String> = ORDERS
            .iter()
            .map(|&o| {
                format!(
                    "{} {} {}, curvature {}, critical {}",
                    o.name(),
                    Measure::Response.name(),
                    self.theory(Measure::Response, o),
                    self.theory(Measure::Curvature, o),
                    self.theory(Measure::Critical, o)
                )
            })
            .collect();
        lines.push(format!("theoretical orders in h: {}", theory.join("; ")));
        lines
    }

    fn csv(&self) -> String {
        let rows = self.rungs.iter().map(|r| {
            let values = r.values.as_ref();
            RungRow {
                discretisation: r.rung.order.name(),
                elements_asked: r.rung.elements,
                elements: r.elements(),
                unknowns: values.ok().map(|v| v.unknowns),
                time_s: r.time.as_secs_f64(),
                response: values.ok().map(|v| v.response),
                critical: values.ok().and_then(|v| v.critical),
                error_response: r.errors[0],
                error_curvature: r.errors[1],
                error_critical: r.errors[2],
                order_response: r.observed[0],
                order_curvature: r.observed[1],
                order_critical: r.observed[2],
                by_construction: u8::from(r.by_construction),
                failure: values.err().map(|e| e.to_string().replace('"', "'")),
            }
        });
        table(&self.header(), rows)
    }

    fn points(&self, order: Order, m: Measure) -> Vec<chart::Point> {
        self.of_order(order)
            .filter_map(|r| {
                let e = r.error(m).filter(|e| *e > 0.0)?;
                let t = r.time.as_secs_f64();
                (t > 0.0).then(|| chart::Point {
                    x: t,
                    y: e,
                    label: r.elements().to_string(),
                    hollow: r.by_construction,
                })
            })
            .collect()
    }

    fn svg(&self) -> Result<String, chart::DrawError> {
        self.svg_for("")
    }

    fn svg_for(&self, command: &str) -> Result<String, chart::DrawError> {
        let panels: Vec<Panel> = Measure::ALL
            .into_iter()
            .filter(|&m| m == Measure::Response || self.has(m))
            .map(|m| Panel {
                title: match m {
                    Measure::Response => format!("{} (relative error)", self.response_label),
                    Measure::Curvature => "curvature profiles (max norm, relative)".to_string(),
                    Measure::Critical => "first critical load (relative error)".to_string(),
                },
                x_label: "wall time of the whole solve (s)".to_string(),
                y_label: "relative error (–)".to_string(),
                series: ORDERS
                    .iter()
                    .map(|&o| Series {
                        label: match self.finest_observed(m, o) {
                            Some(k) => {
                                format!("{}: order {k:.2} (theory {})", o.name(), self.theory(m, o))
                            }
                            None => o.name().to_string(),
                        },
                        points: self.points(o, m),
                        style: series_style(o),
                    })
                    .collect(),
            })
            .collect();
        let title = format!("work-precision: {} ({})", self.name, self.description);
        let mut notes = vec![
            format!("reference: {}", describe_reference(&self.reference)),
            format!(
                "time of the whole solve: {}; points labelled by elements per rod; legend: orders observed in h (element length) between the two finest meshes",
                self.timing()
            ),
        ];
        if matches!(self.reference, Reference::Richardson { .. }) {
            notes.push(
                "hollow marker: the finest mesh of the reference, whose error is the extrapolation's own estimate (its order is the theoretical one by construction)"
                    .to_string(),
            );
        }
        if !command.is_empty() {
            notes.push(format!("command: {command}"));
        }
        chart::log_log_svg(&title, &notes, &panels)
    }
}

/// What the errors of a study are measured against, one line for titles and headers.
/// A few words for a chart's corner: `closed form`, or `Richardson quadratic 16/32` (the
/// order and the elements per rod of the two solutions).
pub fn reference_label(reference: &Reference) -> String {
    match reference {
        Reference::ClosedForm(_) => "closed form".to_string(),
        Reference::Richardson {
            order, elements, ..
        } => format!(
            "Richardson {} {}/{}",
            order.name(),
            elements[0],
            elements[1]
        ),
    }
}

fn describe_reference(reference: &Reference) -> String {
    match reference {
        Reference::ClosedForm(what) => format!("closed form: {what}"),
        Reference::Richardson {
            order,
            elements,
            exponents,
            ..
        } => format!(
            "Richardson extrapolation of {} {} and {} elements/rod with the theoretical orders ({} {}, {} {}, {} {})",
            order.name(),
            elements[0],
            elements[1],
            Measure::Response.name(),
            exponents[0],
            Measure::Curvature.name(),
            exponents[1],
            Measure::Critical.name(),
            exponents[2]
        ),
    }
}

fn short_name(m: Measure) -> &'static str {
    match m {
        Measure::Response => "Fz",
        Measure::Curvature => "curv.",
        Measure::Critical => "crit.",
    }
}

/// Colour and marker of an element order in charts.
pub fn series_style(order: Order) -> chart::Style {
    match order {
        Order::Linear => chart::Style {
            color: "#1f77b4",
            marker: chart::Marker::Circle,
        },
        Order::Quadratic => chart::Style {
            color: "#d62728",
            marker: chart::Marker::Square,
        },
    }
}

/// How a mesh was chosen for an accuracy, as text.
pub trait ChoiceReport {
    /// One line for reports: the chosen mesh and the estimated relative error `estimated`.
    fn note(&self, estimated: f64) -> String;
    /// How the choice was made, one line per element order.
    fn pilot_lines(&self) -> Vec<String>;
}

impl ChoiceReport for MeshChoice {
    fn note(&self, estimated: f64) -> String {
        format!(
            "mesh chosen for accuracy {:e} on {}: {} elements, {} per rod, estimated relative error {:.1e}",
            self.target,
            self.response,
            self.order.name(),
            self.elements,
            estimated
        )
    }

    fn pilot_lines(&self) -> Vec<String> {
        self.pilots
            .iter()
            .map(|p| {
                let need = match (p.needed, p.predicted_time) {
                    (Some(n), Some(t)) => format!(
                        "needs {n} per rod, predicted {:.1} ms",
                        t.as_secs_f64() * 1e3
                    ),
                    _ => format!("needs more than {MAX_ELEMENTS} per rod"),
                };
                let critical = p.critical.as_ref().map_or(String::new(), |c| {
                    format!(
                        ", first critical point's {:.2e} (order {})",
                        c.error, c.exponent
                    )
                });
                format!(
                    "{}: {} and {} elements/rod in {:.1} and {:.1} ms, estimated error {:.2e} (order {}){critical}: {need}",
                    p.order.name(),
                    p.elements[0],
                    p.elements[1],
                    p.time[0].as_secs_f64() * 1e3,
                    p.time[1].as_secs_f64() * 1e3,
                    p.error,
                    p.exponent
                )
            })
            .collect()
    }
}
