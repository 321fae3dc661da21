//! What the viewer reads and writes: scene and fabric TOML, the cloth mesh as OBJ and the
//! test data as CSV. Plain functions from data to text (the dialogs live in `dialogs`), so
//! tests check the formats without a window.

use crate::settings::FabricConfig;
use crate::scene::{Measures, SceneConfig};
use glam::{DVec2, DVec3};
use std::fmt::Write;
use std::path::Path;

/// A scene as TOML that `rosette run FILE` and the viewer's Open read back.
pub fn scene_toml(config: &SceneConfig) -> Result<String, String> {
    // The fabric's texture is found from wherever the scene is saved.
    let mut config = config.clone();
    config.fabric.appearance = config.fabric.appearance.anchored(config.base_dir.as_deref());
    toml::to_string_pretty(&config).map_err(|e| format!("cannot write the scene as TOML: {e}"))
}

/// A fabric as TOML, a file that a scene's `fabric.preset` can name. The `preset` key is
/// left out: every value is written, so the file stands alone.
pub fn fabric_toml(fabric: &FabricConfig) -> Result<String, String> {
    let fabric = FabricConfig { preset: None, appearance: fabric.appearance.anchored(None), ..fabric.clone() };
    toml::to_string_pretty(&fabric).map_err(|e| format!("cannot write the fabric as TOML: {e}"))
}

/// Reads a fabric file (the format of `presets/fabrics/*.toml`, measurement sheets
/// included) and checks its values.
pub fn read_fabric(path: &Path) -> Result<FabricConfig, String> {
    let text = crate::io::read::read_text(path, crate::io::read::FileKind::Fabric).map_err(|e| e.to_string())?;
    let fabric = crate::fabric::parse_fabric(&text, &path.display().to_string()).map_err(|e| e.to_string())?.config;
    if fabric.preset.is_some() {
        return Err(format!(
            "{}: a fabric file opened in the viewer must give every value itself (remove `preset`)",
            path.display()
        ));
    }
    Ok(fabric)
}

/// The cloth as a Wavefront OBJ: positions (m), texture coordinates from the rest
/// positions (m in the sample plane) and faces.
pub fn mesh_obj(positions: &[DVec3], rest: &[DVec2], triangles: &[[u32; 3]]) -> String {
    let mut out = String::from("# Rosette cloth mesh; positions in metres, vt = rest position in the sample plane (m)\n");
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    for r in rest {
        let _ = writeln!(out, "vt {} {}", r.x, r.y);
    }
    for t in triangles {
        let [a, b, c] = t.map(|v| v + 1);
        let _ = writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}");
    }
    out
}

/// Test data as CSV: the rig's final scalar measures (`measure,value`, each number as the
/// metrics JSON writes it), then each of its series that has rows as its own table after
/// a blank line, its columns named `series.column` (see [`Measures::series`]), then the
/// scalar measures sampled over time while the viewer watched (`history`: time, then
/// `names`).
pub fn measures_csv(measures: &Measures, names: &[String], history: &[(f64, Vec<f64>)]) -> String {
    let mut out = String::from("measure,value\n");
    for (name, value) in measures.scalars() {
        let _ = writeln!(out, "{name},{value}");
    }
    for series in measures.series() {
        if series.rows.is_empty() {
            continue;
        }
        let header: Vec<String> = series.columns.iter().map(|c| format!("{}.{c}", series.name)).collect();
        let _ = writeln!(out, "\n{}", header.join(","));
        for row in series.rows {
            let _ = writeln!(out, "{}", row.iter().map(f64::to_string).collect::<Vec<_>>().join(","));
        }
    }
    if !history.is_empty() {
        let _ = writeln!(out, "\ntime_s,{}", names.join(","));
        for (t, values) in history {
            let _ = writeln!(out, "{t},{}", values.iter().map(f64::to_string).collect::<Vec<_>>().join(","));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;
    use crate::scene::measures::{DrapeMeasures, TensileMeasures};

    #[test]
    fn scene_toml_loads_back_to_the_same_scene() {
        let (config, _) = load_scene("cantilever", &["fabric.areal_density=0.31".into()]).unwrap();
        let dir = std::env::temp_dir().join(format!("rosette-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.toml");
        std::fs::write(&path, scene_toml(&config).unwrap()).unwrap();
        let (back, _) = load_scene(path.to_str().unwrap(), &[]).unwrap();
        assert_eq!(back.fabric.properties.areal_density, 0.31);
        assert_eq!(scene_toml(&back).unwrap(), scene_toml(&config).unwrap());

        let fabric_path = dir.join("fabric.toml");
        std::fs::write(&fabric_path, fabric_toml(&config.fabric).unwrap()).unwrap();
        let fabric = read_fabric(&fabric_path).unwrap();
        assert_eq!(fabric.properties.tensile_warp, config.fabric.properties.tensile_warp);
        assert_eq!(fabric.properties.bending_weft, config.fabric.properties.bending_weft);
        std::fs::write(&fabric_path, "areal_density = 0.1\n").unwrap();
        let err = read_fabric(&fabric_path).unwrap_err();
        assert!(err.contains("thickness") || err.contains("missing"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn obj_has_one_based_faces() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let r = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let obj = mesh_obj(&p, &r, &[[0, 1, 2]]);
        assert!(obj.contains("\nv 1 0 0\n"));
        assert!(obj.trim_end().ends_with("f 1/1 2/2 3/3"));
    }

    #[test]
    fn csv_has_scalars_series_and_history() {
        let measures = Measures::Tensile(TensileMeasures {
            final_strain: 0.01,
            final_stress: 2.5,
            poisson_ratio: 0.15,
            stress_strain: vec![[0.0, 0.0], [0.01, 2.5]],
            strain_definition: "text is left out".into(),
            ..Default::default()
        });
        let csv = measures_csv(&measures, &["tip_drop".into()], &[(0.1, vec![0.02])]);
        assert!(csv.starts_with("measure,value\nfinal_strain,0.01\nfinal_stress,2.5\npoisson_ratio,0.15\n"), "{csv}");
        assert!(csv.contains("\nstress_strain.strain,stress_strain.stress_N_per_m\n0,0\n0.01,2.5\n"), "{csv}");
        // Series without rows are left out.
        assert!(!csv.contains("lateral_strain"), "{csv}");
        assert!(csv.contains("\ntime_s,tip_drop\n0.1,0.02\n"), "{csv}");
        assert!(!csv.contains("text is left out"));
    }

    #[test]
    fn csv_writes_counts_as_integers_and_names_the_drape_history_columns() {
        let measures = Measures::Drape(DrapeMeasures { nodes: 6, drape_coefficient: 0.5, history: vec![(0.01, 0.9, 4)], ..Default::default() });
        let csv = measures_csv(&measures, &[], &[]);
        assert!(csv.contains("\nnodes,6\n"), "{csv}");
        assert!(csv.contains("\ndrape_coefficient,0.5\n"), "{csv}");
        assert!(csv.contains("\nhistory.time_s,history.drape_coefficient,history.nodes\n0.01,0.9,4\n"), "{csv}");
    }
}
