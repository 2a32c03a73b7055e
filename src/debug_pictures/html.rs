//! `index.html` of a debug folder: every picture, each with its caption, beside the report's
//! numbers (the lights with their edges and uncertainties, the warnings, the settings). One
//! self-contained page with relative links, to open from the folder.

use crate::report::{EdgeReport, LightReport, Report};

/// A picture of the folder and what it shows.
pub struct Figure {
    /// The file name in the folder.
    pub file: String,
    /// One sentence about it.
    pub caption: String,
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn vec3(v: &[f64; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2])
}

fn sigma(s: Option<f64>) -> String {
    s.map_or("not constrained".into(), |s| format!("&plusmn; {s:.4} m"))
}

fn edge_cell(name: &str, edge: &EdgeReport, s: Option<f64>) -> String {
    format!(
        "<li class=\"edge {}\"><b>{name}</b>: {}, {} px, {}{}</li>",
        escape(&edge.status),
        escape(&edge.status),
        edge.pixels,
        sigma(s),
        edge.reason
            .as_ref()
            .map_or(String::new(), |r| format!(" &mdash; {}", escape(r)))
    )
}

fn light_rows(k: usize, l: &LightReport) -> String {
    let u = l.uncertainty.as_ref();
    let radiance_sigma = u.map_or("none (--method paper)".into(), |u| {
        format!("&plusmn; {}", vec3(&u.radiance))
    });
    format!(
        "<tr class=\"light\" data-light=\"{name}\" data-width=\"{w:.4}\" data-height=\"{h:.4}\">\
         <td>L{k}<br>{name}</td><td>{streaks:?}</td><td>{corner}</td><td>{w:.4} x {h:.4}</td>\
         <td>{rad}<br>{radiance_sigma}</td><td><ul>{edges}</ul></td></tr>\n",
        name = escape(&l.name),
        w = l.width,
        h = l.height,
        streaks = l.streak_ids,
        corner = vec3(&l.corner_left_bottom),
        rad = vec3(&l.radiance),
        edges = [
            edge_cell("left", &l.edges.left, u.and_then(|u| u.left)),
            edge_cell("right", &l.edges.right, u.and_then(|u| u.right)),
            edge_cell("bottom", &l.edges.bottom, u.and_then(|u| u.bottom)),
            edge_cell("top", &l.edges.top, u.and_then(|u| u.top)),
        ]
        .concat(),
    )
}

/// The page for `report` showing `figures`.
pub fn page(report: &Report, figures: &[Figure]) -> String {
    let lights: String = report
        .lights
        .iter()
        .enumerate()
        .map(|(k, l)| light_rows(k, l))
        .collect();
    let warnings: String = report
        .warnings
        .iter()
        .map(|w| format!("<li>{}</li>\n", escape(w)))
        .collect();
    let figures: String = figures
        .iter()
        .map(|f| {
            format!(
                "<figure><img src=\"{file}\" alt=\"{caption}\"><figcaption><b>{file}</b>: \
                 {caption}</figcaption></figure>\n",
                file = escape(&f.file),
                caption = escape(&f.caption)
            )
        })
        .collect();
    let s = &report.settings;
    let skipped: String = report
        .skipped_streaks
        .iter()
        .map(|k| format!("<li>streak S{}: {}</li>\n", k.streak, escape(&k.reason)))
        .collect();
    format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>streaklight fit of {photo}</title>\n<style>\
         body{{font-family:sans-serif;background:#18181c;color:#eee;margin:1.5em}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #555;padding:4px 8px;vertical-align:top}}\
         .unconstrained{{color:#ffb347}}figure{{display:inline-block;margin:0 1em 1em 0}}\
         img{{max-width:100%;border:1px solid #444}}ul{{margin:0;padding-left:1.2em}}\
         </style></head><body>\n\
         <h1>streaklight fit of {photo}</h1>\n\
         <p>Scene {scene}; output {output}; status: {status}. Gloss e = {gloss:.1} ({gloss_source}), \
         IOR {ior}, exposure {exposure} ({exposure_source}), method {method}.</p>\n\
         <h2>Lights ({n})</h2>\n<p>Lengths in metres (world coordinates), radiance in the photo's \
         linear units divided by the exposure; &plusmn; one sigma. L<i>k</i> is the light's \
         number in the pictures.</p>\n\
         <table><tr><th>light</th><th>streaks</th><th>corner (left, bottom)</th>\
         <th>width x height</th><th>radiance</th><th>edges</th></tr>\n{lights}</table>\n\
         <h2>Warnings ({nw})</h2>\n<ul id=\"warnings\">{warnings}</ul>\n\
         <h2>Streaks without a light</h2>\n<ul>{skipped}</ul>\n\
         <h2>Pictures</h2>\n{figures}</body></html>\n",
        photo = escape(&report.files.photo),
        scene = escape(&report.files.scene),
        output = escape(report.files.output.as_deref().unwrap_or("none")),
        status = escape(&report.status),
        gloss = s.gloss,
        gloss_source = escape(&s.gloss_source),
        ior = s.ior,
        exposure = s.exposure,
        exposure_source = escape(&s.exposure_source),
        method = escape(&s.method),
        n = report.lights.len(),
        nw = report.warnings.len(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped() {
        assert_eq!(
            escape("<a href=\"x\">&</a>"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;"
        );
        assert_eq!(sigma(None), "not constrained");
        assert_eq!(sigma(Some(0.01234)), "&plusmn; 0.0123 m");
    }
}
