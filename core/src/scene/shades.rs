//! Operable shades (IES LM-83, the contract's `[[shades]]`): a group of
//! windows (every window of one material) and the material drawn in them
//! when the shade is down.

use std::collections::BTreeMap;

use super::Scene;
use super::error::SceneError;
use super::file::ParsedScene;
use super::material::{Material, MaterialKind};

/// One shade group.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadeGroup {
    /// The windows' material: its index in [`super::Scene::materials`].
    pub windows: u32,
    /// What the windows become when the shade is down (glass or a panel).
    pub shade: Material,
}

/// The scene file's shade groups: `windows` names a glass or panel material
/// the model's faces use, `shade` a glass or panel material of `[materials]`
/// (as the loader built it: in `materials` when faces use it too, else in
/// `unused`).
pub fn shade_groups(
    parsed: &ParsedScene,
    materials: &[Material],
    unused: &BTreeMap<String, Material>,
) -> Result<Vec<ShadeGroup>, SceneError> {
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
            let name = shade.get_ref();
            let built = unused.get(name).or_else(|| materials.iter().find(|m| &m.name == name));
            let Some(material) = built.filter(|_| parsed.materials.contains_key(name)) else {
                return parsed.error(shade.span(), key("shade"), format!("'{name}' is not a material of [materials]"));
            };
            if !transmits(&material.kind) {
                return parsed.error(shade.span(), key("shade"), format!("'{}' is not glass or a panel", shade.get_ref()));
            }
            Ok(ShadeGroup { windows: index as u32, shade: material.clone() })
        })
        .collect()
}

impl Scene {
    /// The scene with the shades of groups `down` (indices into
    /// [`Scene::shades`]) lowered: their windows drawn in the shade's
    /// material. Geometry, patches and sensors stay as they are.
    pub fn with_shades_down(&self, down: &[usize]) -> Scene {
        let mut scene = self.clone();
        for &group in down {
            let ShadeGroup { windows, shade } = &self.shades[group];
            let index = match scene.materials.iter().position(|m| m.name == shade.name) {
                Some(index) => index as u32,
                None => {
                    scene.materials.push(shade.clone());
                    scene.materials.len() as u32 - 1
                }
            };
            let swap = |material: &mut u32| {
                if material == windows {
                    *material = index;
                }
            };
            scene.triangles.iter_mut().for_each(|t| swap(&mut t.material));
            scene.surfaces.iter_mut().for_each(|s| swap(&mut s.material));
            scene.patches.patches.iter_mut().for_each(|p| swap(&mut p.material));
            scene.windows.iter_mut().for_each(|w| swap(&mut w.material));
        }
        scene
    }
}
