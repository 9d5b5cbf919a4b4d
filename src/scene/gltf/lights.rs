//! Lights: `KHR_lights_punctual` and Tesela's `TESELA_light` (including area lights,
//! which become one-sided emissive meshes).

use std::f32::consts::{FRAC_PI_4, PI};

use glam::{Mat4, Vec2, Vec3};
use serde_json::Value;

use super::{LoadError, LoadErrorKind, Loader, LocalPrim, extension, invalid, member, num, rgb};
use crate::scene::{Light, Material, Mesh, SpotFalloff};

/// Lumens per watt used to turn glTF's photometric units into radiometric ones.
pub(crate) const LM_PER_W: f32 = 683.0;

/// Segments of the fan used for disk and ellipse area lights.
pub(crate) const DISK_SEGMENTS: u32 = 64;

/// An area light's outline in its local XY plane, triangulated to face -Z.
pub(crate) fn area_light_prim(shape: &str, sx: f32, sy: f32) -> LocalPrim {
    let (hx, hy) = (0.5 * sx, 0.5 * sy);
    let (positions, tris) = if matches!(shape, "DISK" | "ELLIPSE") {
        let mut p = vec![Vec3::ZERO];
        for k in 0..DISK_SEGMENTS {
            let a = 2.0 * PI * k as f32 / DISK_SEGMENTS as f32;
            p.push(Vec3::new(hx * a.cos(), hy * a.sin(), 0.0));
        }
        // The ring runs counter-clockwise seen from +Z; (centre, next, current) faces -Z.
        let t = (1..=DISK_SEGMENTS)
            .map(|k| [0, k % DISK_SEGMENTS + 1, k])
            .collect();
        (p, t)
    } else {
        let p = vec![
            Vec3::new(-hx, -hy, 0.0),
            Vec3::new(hx, -hy, 0.0),
            Vec3::new(hx, hy, 0.0),
            Vec3::new(-hx, hy, 0.0),
        ];
        (p, vec![[0, 2, 1], [0, 3, 2]])
    };
    LocalPrim {
        positions,
        normals: Vec::new(),
        uvs: Vec::<Vec2>::new(),
        tris,
    }
}

/// Total area of a triangle mesh.
pub(crate) fn mesh_area(p: &[Vec3], tris: &[[u32; 3]]) -> f32 {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

fn valid_color(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

impl<'a> Loader<'a> {
    /// Whether the file was written by Blender's own glTF exporter.
    fn written_by_blender_exporter(&self) -> bool {
        self.root
            .asset
            .generator
            .as_deref()
            .is_some_and(|g| g.starts_with("Khronos glTF Blender I/O"))
    }

    pub(crate) fn node_lights(&mut self, ni: usize, world: Mat4) -> Result<(), LoadError> {
        let raw_node = self.raw_item("nodes", ni);
        if let Some(t) = extension(raw_node, "TESELA_light") {
            return self.tesela_light(ni, world, t);
        }
        let Some(k) = extension(raw_node, "KHR_lights_punctual") else {
            return Ok(());
        };
        let li = member(k, "light").and_then(Value::as_u64).ok_or_else(|| {
            invalid(format!(
                "node {ni}: KHR_lights_punctual has no valid `light` index"
            ))
        })?;
        let lights = extension(self.raw, "KHR_lights_punctual")
            .and_then(|e| member(e, "lights"))
            .and_then(Value::as_array);
        let light = usize::try_from(li)
            .ok()
            .and_then(|i| lights.and_then(|l| l.get(i)))
            .ok_or_else(|| {
                invalid(format!(
                    "node {ni}: KHR_lights_punctual light {li} does not exist (the file has {})",
                    lights.map_or(0, |l| l.len())
                ))
            })?;
        let ty = member(light, "type").and_then(Value::as_str).unwrap_or("");
        let color = rgb(light, "color").unwrap_or(Vec3::ONE);
        let intensity = num(light, "intensity").unwrap_or(1.0) as f32;
        let radiometric = color * intensity / LM_PER_W;
        if !valid_color(radiometric) {
            self.warn_once(format!(
                "KHR_lights_punctual light {li}: invalid color or intensity (skipped)"
            ));
            return Ok(());
        }
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z).try_normalize();
        match (ty, direction) {
            ("point", _) => self.scene.lights.push(Light::Point {
                position,
                intensity: radiometric,
            }),
            ("spot", Some(direction)) => {
                let spot = member(light, "spot").unwrap_or(&Value::Null);
                let outer = (num(spot, "outerConeAngle").unwrap_or(FRAC_PI_4 as f64) as f32)
                    .clamp(1e-4, PI / 2.0);
                let inner =
                    (num(spot, "innerConeAngle").unwrap_or(0.0) as f32).clamp(0.0, outer * 0.9999);
                let inner = if inner.is_finite() { inner } else { 0.0 };
                let falloff = if self.written_by_blender_exporter() {
                    // Blender's exporter writes outer = size/2 and inner = outer·(1 - blend);
                    // Cycles' smoothstep in cos-space is recovered from them
                    // (docs/blender-units.md). inner == outer (blend 0) is a hard edge.
                    let raw_inner = num(spot, "innerConeAngle").unwrap_or(0.0) as f32;
                    let blend = (1.0 - raw_inner / outer).clamp(0.0, 1.0);
                    let blend = if blend.is_finite() { blend } else { 0.0 };
                    let cos_half = outer.cos();
                    SpotFalloff::Cycles {
                        cos_half,
                        smooth: (1.0 - cos_half) * blend,
                    }
                } else {
                    SpotFalloff::Gltf {
                        cos_inner: inner.cos(),
                        cos_outer: outer.cos(),
                    }
                };
                self.scene.lights.push(Light::Spot {
                    position,
                    direction,
                    intensity: radiometric,
                    falloff,
                })
            }
            ("directional", Some(direction)) => self.scene.lights.push(Light::Directional {
                direction,
                irradiance: radiometric,
                angle: 0.0,
            }),
            ("spot" | "directional", None) => self.warn_once(format!(
                "node {ni}: light {li} has a degenerate direction (skipped)"
            )),
            (other, _) => self.warn_once(format!(
                "KHR_lights_punctual light {li}: unknown type `{other}` (skipped)"
            )),
        }
        Ok(())
    }

    fn tesela_light(&mut self, ni: usize, world: Mat4, t: &Value) -> Result<(), LoadError> {
        let ty = member(t, "type").and_then(Value::as_str).unwrap_or("");
        let color = rgb(t, "color").unwrap_or(Vec3::ONE);
        let f = |k: &str, d: f32| num(t, k).map(|v| v as f32).unwrap_or(d);
        let power = f("power", 0.0);
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z).try_normalize();
        let skip = |me: &mut Self, why: &str| {
            me.warn_once(format!("node {ni}: TESELA_light {ty}: {why} (skipped)"));
            Ok(())
        };
        match ty {
            "POINT" | "SPOT" => {
                let intensity = color * power / (4.0 * PI);
                if !valid_color(intensity) {
                    return skip(self, "invalid color or power");
                }
                if ty == "POINT" {
                    self.scene.lights.push(Light::Point {
                        position,
                        intensity,
                    });
                    return Ok(());
                }
                let Some(direction) = direction else {
                    return skip(self, "degenerate direction");
                };
                let size = f("spot_size", FRAC_PI_4);
                let blend = f("spot_blend", 0.15);
                if !(size.is_finite() && blend.is_finite()) {
                    return skip(self, "invalid spot_size or spot_blend");
                }
                let cos_half = (0.5 * size.clamp(0.0, PI)).cos();
                let smooth = (1.0 - cos_half) * blend.clamp(0.0, 1.0);
                self.scene.lights.push(Light::Spot {
                    position,
                    direction,
                    intensity,
                    falloff: SpotFalloff::Cycles { cos_half, smooth },
                });
            }
            "SUN" => {
                let irradiance = color * f("strength", 1.0);
                let angle = f("angle", 0.0);
                let Some(direction) = direction else {
                    return skip(self, "degenerate direction");
                };
                if !valid_color(irradiance) || !angle.is_finite() {
                    return skip(self, "invalid color, strength or angle");
                }
                self.scene.lights.push(Light::Directional {
                    direction,
                    irradiance,
                    angle: angle.clamp(0.0, PI),
                });
            }
            "AREA" => {
                let shape = member(t, "shape")
                    .and_then(Value::as_str)
                    .unwrap_or("SQUARE");
                let size = f("size", 1.0);
                let size_y = match shape {
                    "RECTANGLE" | "ELLIPSE" => f("size_y", size),
                    _ => size,
                };
                if !(size.is_finite() && size_y.is_finite() && size > 0.0 && size_y > 0.0) {
                    return skip(self, "invalid size");
                }
                let local = area_light_prim(shape, size, size_y);
                let Some((positions, _, indices)) = super::mesh::to_world(&local, world) else {
                    return skip(self, "transform overflows");
                };
                let area = mesh_area(&positions, &indices);
                let radiance = color * power / (PI * area);
                if !(area > 0.0 && valid_color(radiance)) {
                    return skip(self, "zero area, or invalid color or power");
                }
                let name = self.root.nodes[ni]
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("area light {ni}"));
                self.scene
                    .materials
                    .push(Material::emitter(&name, radiance, false));
                let material = self.scene.materials.len() - 1;
                self.tri_total = self.tri_total.saturating_add(indices.len());
                self.vert_total = self.vert_total.saturating_add(positions.len());
                if self.tri_total > super::MAX_TRIANGLES {
                    return Err(LoadError::new(
                        LoadErrorKind::TooLarge,
                        "the scene exceeds the triangle limit".to_string(),
                    ));
                }
                self.scene.meshes.push(Mesh {
                    name,
                    positions,
                    normals: Vec::new(),
                    uvs: Vec::new(),
                    indices,
                    material,
                    hidden_from_camera: !member(t, "visible_camera")
                        .and_then(Value::as_bool)
                        .unwrap_or(true),
                    attrs: Default::default(),
                });
            }
            other => {
                return skip(self, &format!("unknown type `{other}`"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face_normal(p: &[Vec3], t: [u32; 3]) -> Vec3 {
        let [a, b, c] = t.map(|i| p[i as usize]);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn area_lights_face_minus_z_with_the_right_area() {
        for (shape, sx, sy) in [
            ("SQUARE", 2.0, 2.0),
            ("RECTANGLE", 2.0, 0.5),
            ("DISK", 1.0, 1.0),
            ("ELLIPSE", 2.0, 1.0),
        ] {
            let l = area_light_prim(shape, sx, sy);
            for t in &l.tris {
                assert!(
                    face_normal(&l.positions, *t).abs_diff_eq(-Vec3::Z, 1e-5),
                    "{shape}"
                );
            }
            let a = mesh_area(&l.positions, &l.tris);
            let want = if shape == "DISK" || shape == "ELLIPSE" {
                // A regular 64-gon inscribed in the ellipse.
                let n = DISK_SEGMENTS as f32;
                0.5 * n * (2.0 * PI / n).sin() * (sx / 2.0) * (sy / 2.0)
            } else {
                sx * sy
            };
            assert!((a - want).abs() < 1e-4 * want, "{shape}: {a} vs {want}");
        }
    }
}
