//! The card's PNG page: the tensile curves against their inputs, shear, the drape from above
//! and the side, and tables of bending, bending lengths, drape and the sheet read back, every
//! value with its unit. Drawn with plotters into an RGB buffer; the drape pictures are
//! rendered separately ([`super::picture`]) and copied in.

use super::picture::{blit, placeholder, wrap};
use super::{Card, Curve};
use image::RgbaImage;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The page, pixels.
pub const SIZE: (u32, u32) = (1400, 920);
/// Each drape picture, pixels.
pub const PICTURE: [u32; 2] = [456, 270];
/// The fabric's swatch at the header's right, pixels.
const SWATCH: [u32; 2] = [210, 50];

const HEADER: u32 = 78;
const ROW: u32 = 310;
const MEASURED: RGBColor = RGBColor(31, 119, 180);
const INPUT: RGBColor = RGBColor(214, 90, 30);
const INK: RGBColor = RGBColor(30, 30, 35);
const GREY: RGBColor = RGBColor(95, 95, 105);
const BAD: RGBColor = RGBColor(190, 30, 30);

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

fn font(size: u32) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", size).into_font()).color(&INK)
}

/// Draws the page for `card`; `pictures` are the drape from above and from the side (or the
/// reason they are missing). Returns the RGB pixels, [`SIZE`].
pub fn draw(card: &Card, pictures: Result<&[RgbaImage; 2], &str>) -> Result<Vec<u8>, String> {
    crate::chart::plot::register_font();
    let mut buffer = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    let picture_at = [(SIZE.0 / 3 + 5, HEADER + ROW + 8), (2 * SIZE.0 / 3 + 5, HEADER + ROW + 8)];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        header(&root, card).map_err(|e| e.to_string())?;
        let body = root.margin(HEADER as i32, 0, 0, 0);
        let (row_a, rest) = body.split_vertically(ROW);
        let (row_b, row_c) = rest.split_vertically(ROW);
        for (panel, t) in row_a.split_evenly((1, 3)).iter().zip(&card.tensile) {
            let e45 = t.e45_formula_n_per_m.map(|e| format!("input: off-axis formula E45 = {e:.1} N/m, small strain"));
            let kes = match (t.emt_percent, t.input_emt_percent, t.lt, t.wt_gf_cm_per_cm2) {
                (Some(emt), Some(input), Some(lt), Some(wt)) => {
                    Some(format!("EMT {emt:.2} % (input {input:.2} %)   LT {lt:.3}   WT {wt:.2} gf·cm/cm²"))
                }
                _ => None,
            };
            let line = kes.or(e45).unwrap_or_default();
            curve_panel(panel, &format!("Tensile, {}", t.direction), &line, &t.measured, &t.input, "input").map_err(|e| e.to_string())?;
        }
        let [shear_area, above_area, side_area] = <[Area; 3]>::try_from(row_b.split_evenly((1, 3))).map_err(|_| "three panels")?;
        let s = &card.shear;
        let top = s.curve.points.iter().map(|p| p[0]).fold(0.0, f64::max);
        let input = Curve::new(&s.curve.x, &s.curve.y, vec![[0.0, 0.0], [top, s.input_modulus_n_per_m * top.to_radians()]]);
        let line = format!(
            "G {:.2} N/m = {:.3} gf/(cm·deg) (input {:.2} N/m)",
            s.modulus_n_per_m, s.g_gf_per_cm_deg, s.input_modulus_n_per_m
        );
        curve_panel(&shear_area, "Shear (KES-FB1, 20 cm × 5 cm)", &line, &s.curve, &input, "G·γ").map_err(|e| e.to_string())?;
        let d = &card.drape;
        let captions = [
            format!("From above: DC {}, {} nodes", super::dc_text(d.result.drape_coefficient), d.result.nodes),
            format!("From the side: {:.0} mm disc on a {:.0} mm support", d.specimen_diameter_mm, d.support_diameter_mm),
        ];
        for (area, caption) in [above_area, side_area].iter().zip(captions) {
            area.draw_text(&caption, &font(15), (8, PICTURE[1] as i32 + 12)).map_err(|e| e.to_string())?;
        }
        tables(&row_c, card).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let owned;
    let pictures = match pictures {
        Ok(p) => p,
        Err(message) => {
            let missing = placeholder(PICTURE, &format!("drape not rendered: {message}"));
            owned = [missing.clone(), missing];
            &owned
        }
    };
    for (picture, at) in pictures.iter().zip(picture_at) {
        let picture = if picture.dimensions() == (PICTURE[0], PICTURE[1]) {
            picture.clone()
        } else {
            image::imageops::resize(picture, PICTURE[0], PICTURE[1], image::imageops::FilterType::Triangle)
        };
        blit(&mut buffer, SIZE.0, &picture, at);
    }
    let look = crate::appearance::Look::or_default(&card.fabric.appearance, None);
    blit(&mut buffer, SIZE.0, &crate::appearance::shade::swatch(&look, SWATCH), (SIZE.0 - SWATCH[0] - 12, 6));
    Ok(buffer)
}

fn header(root: &Area, card: &Card) -> DrawResult {
    let f = &card.fabric;
    root.draw_text(&format!("Fabric card: {}", f.name), &font(26), (16, 10))?;
    // Under the swatch (drawn over the page afterwards, at its right): the look in words.
    let look = crate::appearance::Look::or_default(&f.appearance, None).summary();
    root.draw_text(&look, &font(11).color(&GREY), (SIZE.0 as i32 - SWATCH[0] as i32 - 12, 60))?;
    let facts = format!(
        "{} · {:.0} g/m² · {:.3} mm thick · ν = {:.2} · virtual laboratory of rosette {}",
        f.source,
        f.areal_density_g_per_m2,
        f.thickness_mm,
        f.poisson_warp,
        env!("CARGO_PKG_VERSION")
    );
    root.draw_text(&facts, &font(14).color(&GREY), (16, 44))?;
    if let Some(line) = wrap(&f.description, 150).first() {
        root.draw_text(line, &font(14).color(&GREY), (16, 61))?;
    }
    Ok(())
}

/// A panel of `measured` (solid, with its points) against `input` (dashed), with a title
/// and one line of numbers under it.
fn curve_panel(area: &Area, title: &str, line: &str, measured: &Curve, input: &Curve, input_name: &str) -> DrawResult {
    area.draw_text(title, &font(17), (14, 4))?;
    area.draw_text(line, &font(13).color(&GREY), (14, 26))?;
    let plot = area.margin(44, 6, 4, 10);
    let all = measured.points.iter().chain(&input.points);
    let x_max = all.clone().map(|p| p[0]).fold(0.0, f64::max).max(1e-9) * 1.04;
    let y_max = all.map(|p| p[1]).fold(0.0, f64::max).max(1e-9) * 1.06;
    let mut chart = ChartBuilder::on(&plot).x_label_area_size(36).y_label_area_size(58).build_cartesian_2d(0.0..x_max, 0.0..y_max)?;
    chart
        .configure_mesh()
        .x_desc(measured.x.as_str())
        .y_desc(measured.y.as_str())
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .light_line_style(RGBColor(238, 238, 240))
        .draw()?;
    let pairs = |c: &Curve| c.points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>();
    chart
        .draw_series(LineSeries::new(pairs(input), INPUT.mix(0.45).stroke_width(6)))?
        .label(input_name)
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], INPUT.mix(0.45).stroke_width(6)));
    chart
        .draw_series(LineSeries::new(pairs(measured), MEASURED.stroke_width(2)))?
        .label("virtual test")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], MEASURED.stroke_width(2)));
    chart.draw_series(pairs(measured).into_iter().map(|p| Circle::new(p, 2, MEASURED.filled())))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(170, 170, 170))
        .label_font(("sans-serif", 13))
        .draw()?;
    Ok(())
}

/// Rows of text at fixed column offsets under a heading.
struct Table<'a, 'b> {
    area: &'a Area<'b>,
    y: i32,
}

impl Table<'_, '_> {
    fn heading(&mut self, text: &str) -> DrawResult {
        self.area.draw_text(text, &font(16), (12, self.y))?;
        self.y += 22;
        Ok(())
    }

    fn row(&mut self, cells: &[(i32, String)], style: &TextStyle) -> DrawResult {
        for (x, text) in cells {
            self.area.draw_text(text, style, (12 + x, self.y))?;
        }
        self.y += 17;
        Ok(())
    }
}

fn tables(area: &Area, card: &Card) -> DrawResult {
    let columns = area.split_evenly((1, 4));
    let small = font(13);
    let grey = font(12).color(&GREY);
    // Bending.
    let mut t = Table { area: &columns[0], y: 8 };
    t.heading("Pure bending B (KES-FB2), µN·m")?;
    t.row(&[(0, "cut".into()), (60, "virtual".into()), (140, "input".into()), (210, "gf·cm²/cm".into())], &grey)?;
    for b in &card.pure_bending {
        let cells = [(0, b.direction.clone()), (60, format!("{:.3}", b.rigidity_un_m)), (140, format!("{:.3}", b.input_rigidity_un_m)), (210, format!("{:.4}", b.rigidity_gf_cm2_per_cm))];
        t.row(&cells, &small)?;
    }
    t.y += 6;
    t.row(&[(0, "read between 0.5 and 1.5 1/cm; bias input: eq. 3".into())], &grey)?;
    // Cantilever.
    let mut t = Table { area: &columns[1], y: 8 };
    t.heading("Bending length c (ASTM D1388), mm")?;
    t.row(&[(0, "cut".into()), (60, "virtual".into()), (140, "(B/w)^⅓".into()), (220, "overhang".into())], &grey)?;
    for c in &card.cantilever {
        let cells = [(0, c.direction.clone()), (60, format!("{:.2}", c.bending_length_mm)), (140, format!("{:.2}", c.formula_bending_length_mm)), (220, format!("{:.1}", c.overhang_mm))];
        t.row(&cells, &small)?;
    }
    t.y += 6;
    let width = card.cantilever.first().map_or(25.0, |c| c.strip_width_mm);
    t.row(&[(0, format!("{width:.0} mm strips, chord at 41.5°; w = ρ·g"))], &grey)?;
    t.row(&[(0, "a free bias strip twists, so reads below eq. 3".into())], &grey)?;
    // Drape and cost.
    let d = &card.drape;
    let mut t = Table { area: &columns[2], y: 8 };
    t.heading(&format!("Cusick drape ({})", d.scene))?;
    let lines = [
        format!("drape coefficient DC  {}", super::dc_text(d.result.drape_coefficient)),
        format!("nodes  {}", d.result.nodes),
        format!("shadow radius  {:.1} to {:.1} mm", d.result.outline_radius_min_mm, d.result.outline_radius_max_mm),
        d.result.settle_status(),
        format!("mesh  {} triangles, {:.1} mm edges", d.triangles, d.edge_length_mm),
    ];
    for line in lines {
        t.row(&[(0, line)], &small)?;
    }
    if !d.result.converged {
        t.row(&[(0, "some Newton solves did not converge".into())], &font(13).color(&BAD))?;
    }
    t.y += 6;
    let c = &card.cost;
    t.row(&[(0, format!("card: {:.1} CPU s, {:.1} s wall on {} threads", c.cpu_seconds, c.wall_seconds, c.threads))], &grey)?;
    // The sheet read back.
    let mut t = Table { area: &columns[3], y: 8 };
    t.heading("Sheet read back")?;
    if card.sheet_readback.is_empty() {
        t.row(&[(0, "given by its keys: no sheet to read back".into())], &grey)?;
        return Ok(());
    }
    t.row(&[(0, "field, unit".into()), (150, "sheet".into()), (205, "virtual".into()), (265, "error".into())], &grey)?;
    // As many rows as the space holds, the rest in the JSON.
    let shown = if card.sheet_readback.len() > 8 { 7 } else { card.sheet_readback.len() };
    for v in &card.sheet_readback[..shown] {
        let style = match (v.held, v.passes) {
            (false, _) => grey.clone(),
            (true, true) => small.clone(),
            (true, false) => font(13).color(&BAD),
        };
        let field = format!("{} {}", v.field.replace(" → 123/EB5", ""), v.unit);
        let cells = [(0, field), (150, format!("{:.4}", v.sheet)), (205, format!("{:.4}", v.measured)), (265, format!("{:+.2} %", v.error_percent))];
        t.row(&cells, &style)?;
    }
    if shown < card.sheet_readback.len() {
        t.row(&[(0, format!("… {} more in the JSON", card.sheet_readback.len() - shown))], &grey)?;
    }
    let outside = card.sheet_readback.iter().filter(|v| !v.passes).count();
    let held = card.sheet_readback.iter().filter(|v| v.held).count();
    let reported = match card.sheet_readback.len() - held {
        0 => String::new(),
        n => format!("; {n} grey: dropped by the import, reported"),
    };
    let verdict = match outside {
        0 => (format!("all {held} within tolerance{reported}"), grey),
        n => (format!("{n} of {held} outside tolerance{reported}"), font(13).color(&BAD)),
    };
    t.row(&[(0, verdict.0)], &verdict.1)?;
    Ok(())
}
