//! A fabric check that fails on a key the sheet gave, said in the sheet's terms: the user
//! wrote `kes.LT_warp = 0.001`, not `fabric.tensile_warp`, and a default the sheet never
//! set (`poisson_warp`) is not the value to blame.

use super::derived::Import;

/// The keys a fabric check weighs together: the Poisson ratio is refused against the
/// tensile curves, the bias rigidity against the warp and weft rigidities.
fn weighed_with(key: &str) -> &'static [&'static str] {
    match key {
        "poisson_warp" => &["tensile_warp", "tensile_weft"],
        "bending_bias" => &["bending_warp", "bending_weft"],
        _ => &[],
    }
}

/// The sheet fields a source line quotes, each as `section.FIELD = VALUE UNIT`, in order.
pub fn quoted_fields(source: &str) -> Vec<String> {
    let mut fields = Vec::new();
    for section in ["kes.", "fast.", "cantilever."] {
        let mut rest = source;
        while let Some(at) = rest.find(section) {
            let after = &rest[at..];
            // Up to the next separator the source lines use between fields.
            let end = [",", ":", ";", "(", " with ", " on "].iter().filter_map(|p| after.find(p)).min().unwrap_or(after.len());
            let field = after[..end].trim().to_string();
            if !fields.contains(&field) {
                fields.push(field);
            }
            rest = &after[section.len()..];
        }
    }
    // In the order the source line gives them.
    fields.sort_by_key(|f| source.find(f.as_str()).unwrap_or(usize::MAX));
    fields
}

/// The names alone (`kes.LT_warp`) of quoted fields.
pub fn field_names(fields: &[String]) -> Vec<String> {
    fields.iter().map(|f| f.split(" = ").next().unwrap_or(f).trim().to_string()).collect()
}

/// The failed check on fabric key `key` (its message `message`) in the sheet's terms, with
/// the sheet fields behind it; None where no measured sheet value lies behind the keys the
/// check weighs (the fabric's own keys are then the ones to name).
pub fn explain(import: &Import, key: &str, message: &str) -> Option<(String, Vec<String>)> {
    let measured = |k: &str| import.get(k).filter(|d| !d.default);
    let mut keys: Vec<&str> = Vec::new();
    let own = measured(key).is_some();
    if own {
        keys.push(key);
    }
    keys.extend(weighed_with(key).iter().copied().filter(|k| measured(k).is_some()));
    let fields: Vec<String> = keys.iter().flat_map(|k| quoted_fields(&measured(k).expect("measured").source)).fold(Vec::new(), |mut all, f| {
        if !all.contains(&f) {
            all.push(f);
        }
        all
    });
    if fields.is_empty() {
        return None;
    }
    let behind = keys.iter().map(|k| format!("fabric.{k}")).collect::<Vec<_>>().join(" and ");
    let default = match import.get(key) {
        Some(d) if d.default && !own => format!(" (fabric.{key} is a default: {})", d.source.trim_start_matches("default: ")),
        _ => String::new(),
    };
    let text = format!(
        "{}: the sheet values behind {behind} fail the fabric's check{default}: {message}. Check these values on the sheet (their units too)",
        fields.join(", ")
    );
    Some((text, field_names(&fields)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_read_from_a_source_line_in_its_order() {
        let source = "kes.EMT_warp = 5.5 %, kes.LT_warp = 0.001, kes.WT_warp = 8.9 gf·cm/cm², Fm = 500 gf/cm: the two-segment KES curve";
        assert_eq!(quoted_fields(source), ["kes.EMT_warp = 5.5 %", "kes.LT_warp = 0.001", "kes.WT_warp = 8.9 gf·cm/cm²"]);
        assert_eq!(field_names(&quoted_fields("cantilever.c_warp = 15 mm with cantilever.W = 168 g/m²: B = W·g·c³")), ["cantilever.c_warp", "cantilever.W"]);
    }
}
