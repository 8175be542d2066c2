//! The Markdown report of a benchmark's results (one [`PresetResult`] per shadow technique
//! preset, each with one [`SceneResult`] per scene; the types live in
//! [`results`](crate::analysis::results) and are re-exported here).
//!
//! Numbers are formatted the same everywhere: milliseconds with 3 decimals, errors and
//! shimmer spreads (shadow-factor units) with 4, rates as percent with 2; a value that is not
//! finite shows as `—`.

use std::fmt::{self, Write};

use crate::analysis::pareto::pareto_front;
pub use crate::analysis::results::{BenchReport, GpuTimes, PresetResult, SceneResult, ScoredLight};

/// How a column's numbers are written.
#[derive(Clone, Copy)]
enum Unit {
    Ms,
    Error,
    Percent,
}

/// The columns shared by the headline and the per-scene tables.
const COLUMNS: [(&str, Unit); 10] = [
    ("GPU ms", Unit::Ms),
    ("Shadow ms", Unit::Ms),
    ("Forward ms", Unit::Ms),
    ("Penumbra MAE", Unit::Error),
    ("MAE", Unit::Error),
    ("p95", Unit::Error),
    ("Acne %", Unit::Percent),
    ("Leak %", Unit::Percent),
    ("Shimmer (translation)", Unit::Error),
    ("Shimmer (rotation)", Unit::Error),
];

/// The values of [`COLUMNS`] for one scene.
fn columns(s: &SceneResult) -> [f64; 10] {
    [
        s.gpu.total_ms,
        s.gpu.shadow_ms,
        s.gpu.forward_ms,
        s.errors.penumbra_mae,
        s.errors.mae,
        s.errors.p95,
        s.errors.acne_rate,
        s.errors.leak_rate,
        s.shimmer_translation.mean_spread,
        s.shimmer_rotation.mean_spread,
    ]
}

/// Writes `v` in `unit`, or `—` when it is not finite.
fn number(v: f64, unit: Unit) -> String {
    match unit {
        _ if !v.is_finite() => "—".to_owned(),
        Unit::Ms => format!("{v:.3}"),
        Unit::Error => format!("{v:.4}"),
        Unit::Percent => format!("{:.2}", v * 100.0),
    }
}

/// `text` made safe for one table cell or list line.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// The Markdown report; `plot_file` is the plot image's path relative to the report.
pub fn markdown(report: &BenchReport, plot_file: Option<&str>) -> String {
    let mut out = String::new();
    write_markdown(&mut out, report, plot_file).expect("formatting into a String cannot fail");
    out
}

fn write_markdown(out: &mut String, r: &BenchReport, plot_file: Option<&str>) -> fmt::Result {
    writeln!(out, "# {}\n", cell(&r.title))?;
    writeln!(out, "- **Adapter:** {}", cell(&r.adapter))?;
    writeln!(out, "- **Driver:** {}", cell(&r.driver))?;
    writeln!(out, "- **Backend:** {}", cell(&r.backend))?;
    writeln!(out, "- **Commit:** `{}`", cell(&r.commit))?;
    writeln!(out, "- **Date:** {}", cell(&r.date))?;
    writeln!(
        out,
        "- **Timing:** {}×{}, median of {} frames per scene and preset",
        r.width, r.height, r.timing_frames
    )?;
    writeln!(out, "- **Error analysis:** {}×{}", r.analysis_width, r.analysis_height)?;
    writeln!(out, "- **Reference:** ray traced, {}", cell(&r.reference_samples))?;

    let scenes = scene_names(r);
    writeln!(out, "\n## Summary\n")?;
    writeln!(
        out,
        "Means over {} scene(s). Times are per frame at {}×{}; errors are in shadow-factor units \
         (0 = shadowed, 1 = lit) at {}×{}; shimmer is the mean spread (max − min) of the shadow \
         at fixed world points while the camera moves. ✓ marks the Pareto front of GPU ms against \
         penumbra MAE.\n",
        scenes.len(),
        r.width,
        r.height,
        r.analysis_width,
        r.analysis_height
    )?;
    table_header(out, &[])?;
    for (p, on_front) in r.presets.iter().zip(r.pareto_front()) {
        let mut means = [0.0; 10];
        for (i, m) in means.iter_mut().enumerate() {
            *m = p.mean(|s| columns(s)[i]);
        }
        table_row(out, &cell(&p.preset), &means, &[], on_front)?;
    }
    let described: Vec<&PresetResult> = r.presets.iter().filter(|p| !p.description.trim().is_empty()).collect();
    if !described.is_empty() {
        writeln!(out)?;
        for p in described {
            writeln!(out, "- **{}**: {}", cell(&p.preset), cell(&p.description))?;
        }
    }

    for scene in &scenes {
        writeln!(out, "\n## Scene: {}\n", cell(scene))?;
        table_header(out, &["CPU ms", "Draw calls", "Shadow MiB"])?;
        let rows: Vec<(&PresetResult, &SceneResult)> = r
            .presets
            .iter()
            .filter_map(|p| Some((p, p.scenes.iter().find(|s| &s.scene == scene)?)))
            .collect();
        let points: Vec<(f64, f64)> = rows
            .iter()
            .map(|(_, s)| (s.gpu.total_ms, s.errors.penumbra_mae))
            .collect();
        for ((p, s), on_front) in rows.iter().zip(pareto_front(&points)) {
            let extra = [
                number(s.cpu_ms, Unit::Ms),
                s.draw_calls.to_string(),
                format!("{:.2}", s.shadow_memory_bytes as f64 / (1024.0 * 1024.0)),
            ];
            table_row(out, &cell(&p.preset), &columns(s), &extra, on_front)?;
        }
    }

    writeln!(out, "\n## Penumbra MAE per cascade\n")?;
    let single_view = r.presets.iter().flat_map(|p| &p.scenes).any(|s| s.light.views() < 4);
    if single_view {
        writeln!(
            out,
            "`—`: no penumbra pixel in that cascade. `n/a`: the scored light has no such view (a spot light has one, and a point light's six faces count as one; each shown as cascade 0).\n"
        )?;
    } else {
        writeln!(out, "`—`: no penumbra pixel in that cascade.\n")?;
    }
    writeln!(
        out,
        "| Preset | Scene | Cascade 0 | Cascade 1 | Cascade 2 | Cascade 3 |"
    )?;
    writeln!(out, "|---|---|---:|---:|---:|---:|")?;
    for p in &r.presets {
        for s in &p.scenes {
            write!(out, "| {} | {} |", cell(&p.preset), cell(&s.scene))?;
            for (i, c) in s.per_cascade.iter().enumerate() {
                if i >= s.light.views() {
                    write!(out, " n/a |")?;
                    continue;
                }
                let v = if c.penumbra_pixels == 0 {
                    f64::NAN
                } else {
                    c.penumbra_mae
                };
                write!(out, " {} |", number(v, Unit::Error))?;
            }
            writeln!(out)?;
        }
    }

    write_contact_band(out, r)?;

    if let Some(plot) = plot_file {
        writeln!(out, "\n## GPU time against penumbra error\n")?;
        writeln!(out, "![GPU time against penumbra MAE, one point per preset]({plot})")?;
    }

    let notes = notes(r);
    if !notes.is_empty() {
        writeln!(out, "\n## Notes\n")?;
        for n in notes {
            writeln!(out, "- {}", cell(&n))?;
        }
    }
    Ok(())
}

/// The image's own errors (contact shadows included), over the whole frame and over the
/// contact band: per preset and scene.
fn write_contact_band(out: &mut String, r: &BenchReport) -> fmt::Result {
    writeln!(out, "\n## Contact band\n")?;
    writeln!(
        out,
        "Scored from the image's own shadow factor (the filter times contact shadows), over every point and over the contact band: the points within 0.3 m of a caster (on the side their normal faces), where casters meet their receivers. `—`: no such point.\n"
    )?;
    writeln!(
        out,
        "| Preset | Scene | Penumbra MAE | Acne % | Leak % | Band points | Band MAE | Band penumbra MAE | Band acne % | Band leak % |"
    )?;
    writeln!(out, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    for p in &r.presets {
        for s in &p.scenes {
            let (f, c) = (&s.image_errors, &s.contact_band);
            let band = |v: f64| if c.pixels == 0 { f64::NAN } else { v };
            writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                cell(&p.preset),
                cell(&s.scene),
                number(f.penumbra_mae, Unit::Error),
                number(f.acne_rate, Unit::Percent),
                number(f.leak_rate, Unit::Percent),
                c.pixels,
                number(band(c.mae), Unit::Error),
                number(band(c.penumbra_mae), Unit::Error),
                number(band(c.acne_rate), Unit::Percent),
                number(band(c.leak_rate), Unit::Percent),
            )?;
        }
    }
    Ok(())
}

/// Scene names in order of first appearance.
fn scene_names(r: &BenchReport) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for s in r.presets.iter().flat_map(|p| &p.scenes) {
        if !names.contains(&s.scene) {
            names.push(s.scene.clone());
        }
    }
    names
}

/// The report's notes, then one per result that skipped NaN pixels or points.
fn notes(r: &BenchReport) -> Vec<String> {
    let mut notes = r.notes.clone();
    for p in &r.presets {
        for s in &p.scenes {
            let (pixels, t, rot) = (
                s.errors.skipped_nan,
                s.shimmer_translation.skipped_nan,
                s.shimmer_rotation.skipped_nan,
            );
            if pixels + t + rot > 0 {
                notes.push(format!(
                    "{} on {}: skipped for NaN: {pixels} pixel(s), {t} translation and {rot} rotation shimmer point(s)",
                    p.preset, s.scene
                ));
            }
        }
    }
    notes
}

fn table_header(out: &mut String, extra: &[&str]) -> fmt::Result {
    write!(out, "| Preset |")?;
    for name in COLUMNS.iter().map(|c| c.0).chain(extra.iter().copied()) {
        write!(out, " {name} |")?;
    }
    writeln!(out, " Pareto |")?;
    writeln!(out, "|---|{}:---:|", "---:|".repeat(COLUMNS.len() + extra.len()))
}

fn table_row(out: &mut String, name: &str, values: &[f64; 10], extra: &[String], on_front: bool) -> fmt::Result {
    write!(out, "| {name} |")?;
    for (v, (_, unit)) in values.iter().zip(COLUMNS) {
        write!(out, " {} |", number(*v, unit))?;
    }
    for e in extra {
        write!(out, " {e} |")?;
    }
    writeln!(out, " {} |", if on_front { "✓" } else { "" })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::analysis::edges::EdgeSplit;
    use crate::analysis::metrics::ErrorMetrics;
    use crate::analysis::shimmer::Shimmer;

    fn scene(name: &str, total_ms: f64, penumbra_mae: f64) -> SceneResult {
        let errors = ErrorMetrics {
            pixels: 100,
            mae: penumbra_mae / 2.0,
            penumbra_pixels: 50,
            penumbra_mae,
            ..ErrorMetrics::default()
        };
        SceneResult {
            scene: name.to_owned(),
            gpu: GpuTimes {
                shadow_ms: total_ms * 0.25,
                forward_ms: total_ms * 0.5,
                total_ms,
            },
            cpu_ms: 0.125,
            draw_calls: 42,
            shadow_memory_bytes: 3 * 1024 * 1024,
            light: ScoredLight::Sun { angular_diameter: 0.53 },
            errors,
            per_cascade: [errors, errors, ErrorMetrics::default(), errors],
            shimmer_translation: Shimmer {
                points: 10,
                mean_spread: 0.0123,
                ..Shimmer::default()
            },
            shimmer_rotation: Shimmer {
                points: 10,
                mean_spread: 0.0456,
                ..Shimmer::default()
            },
            edges: EdgeSplit::default(),
            image_errors: errors,
            contact_band: errors,
        }
    }

    fn preset(name: &str, scenes: Vec<SceneResult>) -> PresetResult {
        PresetResult {
            preset: name.to_owned(),
            description: format!("{name} description"),
            scenes,
        }
    }

    /// Four presets on two scenes; means (GPU ms, penumbra MAE): hard (1, 0.3), pcf (2, 0.1),
    /// slow (3, 0.2, dominated by pcf), pcss (4, 0.05).
    pub(crate) fn sample_report() -> BenchReport {
        let presets = vec![
            preset("hard", vec![scene("sponza", 0.5, 0.25), scene("forest", 1.5, 0.35)]),
            preset("pcf", vec![scene("sponza", 2.0, 0.1), scene("forest", 2.0, 0.1)]),
            preset("slow", vec![scene("sponza", 3.0, 0.05), scene("forest", 3.0, 0.35)]),
            preset("pcss", vec![scene("sponza", 4.0, 0.05), scene("forest", 4.0, 0.05)]),
        ];
        BenchReport {
            title: "Shadow presets".to_owned(),
            adapter: "Test GPU 9000".to_owned(),
            driver: "test 1.2.3".to_owned(),
            backend: "Vulkan".to_owned(),
            commit: "abc1234".to_owned(),
            date: "2026-01-02".to_owned(),
            width: 1920,
            height: 1080,
            analysis_width: 960,
            analysis_height: 540,
            reference_samples: "1024 rays per pixel".to_owned(),
            timing_frames: 300,
            presets,
            notes: vec!["first note".to_owned()],
        }
    }

    /// The rows of the table that follows `heading`, as cells.
    fn table_after(md: &str, heading: &str) -> Vec<Vec<String>> {
        let start = md.find(heading).unwrap_or_else(|| panic!("no {heading:?} in\n{md}"));
        md[start..]
            .lines()
            .skip_while(|l| !l.starts_with('|'))
            .take_while(|l| l.starts_with('|'))
            .skip(2)
            .map(|l| l.trim_matches('|').split(" | ").map(|c| c.trim().to_owned()).collect())
            .collect()
    }

    #[test]
    fn means_over_scenes() {
        let r = sample_report();
        assert_eq!(r.presets[0].mean_gpu_ms(), 1.0);
        assert!((r.presets[0].mean_penumbra_mae() - 0.3).abs() < 1e-12);
        assert!(preset("empty", vec![]).mean_gpu_ms().is_nan());
        assert_eq!(r.pareto_front(), [true, true, false, true]);
    }

    #[test]
    fn headline_rows_and_front_marks() {
        let md = markdown(&sample_report(), None);
        let rows = table_after(&md, "## Summary");
        let names: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
        assert_eq!(names, ["hard", "pcf", "slow", "pcss"], "{md}");
        let marked: Vec<bool> = rows.iter().map(|r| r.last().is_some_and(|c| c == "✓")).collect();
        assert_eq!(marked, [true, true, false, true], "{md}");
        // hard: GPU 1.000, shadow 0.250, forward 0.500, penumbra MAE 0.3000, MAE 0.1500.
        assert_eq!(rows[0][1..6], ["1.000", "0.250", "0.500", "0.3000", "0.1500"], "{md}");
        assert_eq!(rows[0][7..11], ["0.00", "0.00", "0.0123", "0.0456"], "{md}");
        assert_eq!(rows[0].len(), 12);
    }

    #[test]
    fn scene_tables_have_their_own_front_and_extra_columns() {
        let md = markdown(&sample_report(), None);
        let sponza = table_after(&md, "## Scene: sponza");
        let marked: Vec<bool> = sponza.iter().map(|r| r.last().is_some_and(|c| c == "✓")).collect();
        // sponza (ms, MAE): hard (0.5, 0.25), pcf (2, 0.1), slow (3, 0.05), pcss (4, 0.05).
        assert_eq!(marked, [true, true, true, false], "{md}");
        assert_eq!(sponza[0][11..14], ["0.125", "42", "3.00"], "{md}");
        let forest = table_after(&md, "## Scene: forest");
        let marked: Vec<bool> = forest.iter().map(|r| r.last().is_some_and(|c| c == "✓")).collect();
        assert_eq!(marked, [true, true, false, true], "{md}");
    }

    #[test]
    fn header_cascades_plot_and_notes() {
        let md = markdown(&sample_report(), Some("plot.png"));
        for needle in [
            "# Shadow presets",
            "Test GPU 9000",
            "test 1.2.3",
            "Vulkan",
            "`abc1234`",
            "2026-01-02",
        ] {
            assert!(md.contains(needle), "{needle:?} missing in\n{md}");
        }
        for needle in [
            "1920×1080",
            "300 frames",
            "960×540",
            "1024 rays per pixel",
            "pcss description",
        ] {
            assert!(md.contains(needle), "{needle:?} missing in\n{md}");
        }
        let cascades = table_after(&md, "## Penumbra MAE per cascade");
        assert_eq!(cascades.len(), 8);
        assert_eq!(
            cascades[0],
            ["hard", "sponza", "0.2500", "0.2500", "—", "0.2500"],
            "{md}"
        );
        assert!(md.contains("](plot.png)"), "{md}");
        assert!(md.contains("\n- first note\n"), "{md}");
        assert!(!markdown(&sample_report(), None).contains("plot.png"));
    }

    #[test]
    fn a_spot_scene_has_one_cascade_column() {
        let mut r = sample_report();
        assert!(
            !markdown(&r, None).contains("n/a"),
            "sun scenes have four cascade columns"
        );
        r.presets[0].scenes[1].light = ScoredLight::Spot { index: 0, radius: 0.25 };
        let md = markdown(&r, None);
        let cascades = table_after(&md, "## Penumbra MAE per cascade");
        assert_eq!(cascades[1], ["hard", "forest", "0.3500", "n/a", "n/a", "n/a"], "{md}");
        assert_eq!(cascades[0][2..], ["0.2500", "0.2500", "—", "0.2500"], "{md}");
        assert!(md.contains("`n/a`: the scored light has no such view"), "{md}");
    }

    #[test]
    fn nan_skips_become_notes_and_pipes_are_escaped() {
        let mut r = sample_report();
        r.presets[1].scenes[0].errors.skipped_nan = 7;
        r.presets[1].preset = "a|b".to_owned();
        let md = markdown(&r, None);
        assert!(md.contains("a\\|b on sponza: skipped for NaN: 7 pixel(s)"), "{md}");
        let rows = table_after(&md, "## Summary");
        assert_eq!(rows[1].len(), 12, "{md}");
    }

    #[test]
    fn numbers_are_formatted_consistently() {
        assert_eq!(number(1.23456, Unit::Ms), "1.235");
        assert_eq!(number(0.123456, Unit::Error), "0.1235");
        assert_eq!(number(0.123456, Unit::Percent), "12.35");
        assert_eq!(number(f64::NAN, Unit::Ms), "—");
    }
}
