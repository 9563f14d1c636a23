//! Operable shades (IES LM-83, the contract's `[[shades]]`): a group of
//! windows (every window of one material) and the material drawn in them
//! when the shade is down.

use super::error::SceneError;
use super::file::ParsedScene;
use super::material::{Material, MaterialKind, scene_material};
use crate::panel::PanelCatalog;

/// One shade group.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadeGroup {
    /// The windows' material: its index in [`super::Scene::materials`].
    pub windows: u32,
    /// What the windows become when the shade is down (glass or a panel).
    pub shade: Material,
}

/// The scene file's shade groups: `windows` names a glass or panel material
/// the model's faces use, `shade` a glass or panel material of `[materials]`.
pub fn shade_groups(parsed: &ParsedScene, materials: &[Material], panels: &PanelCatalog) -> Result<Vec<ShadeGroup>, SceneError> {
    let transmits = |kind: &MaterialKind| matches!(kind, MaterialKind::Glass { .. } | MaterialKind::Panel { .. });
    parsed
        .shades
        .iter()
        .enumerate()
        .map(|(i, entry)| {
            let entry = entry.get_ref();
            let (windows, shade) = (&entry.windows, &entry.shade);
            let key = |k: &str| format!("shades[{i}].{k}");
            let Some(index) = materials.iter().position(|m| &m.name == windows.get_ref()) else {
                return parsed.error(windows.span(), key("windows"), format!("no face of the model uses material '{}'", windows.get_ref()));
            };
            if !transmits(&materials[index].kind) {
                return parsed.error(
                    windows.span(),
                    key("windows"),
                    format!("'{}' is not a window material (glass or panel)", windows.get_ref()),
                );
            }
            let Some(table) = parsed.materials.get(shade.get_ref()) else {
                return parsed.error(shade.span(), key("shade"), format!("'{}' is not a material of [materials]", shade.get_ref()));
            };
            let material = scene_material(parsed, shade.get_ref(), table, panels)?;
            if !transmits(&material.kind) {
                return parsed.error(shade.span(), key("shade"), format!("'{}' is not glass or a panel", shade.get_ref()));
            }
            Ok(ShadeGroup { windows: index as u32, shade: material })
        })
        .collect()
}
