//! Lights: `KHR_lights_punctual` and Tesela's `TESELA_light` (Blender's lights with their
//! native parameters: radius, spot, sun angle, area shape and spread, ray visibility).

use std::f32::consts::{FRAC_PI_4, PI};

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};
use serde_json::Value;

use super::{LoadError, Loader, extension, invalid, member, num, rgb};
use crate::emitter::ies::IesProfile;
use crate::scene::{Light, LightProfile, LightShape, LightVisibility, SpotFalloff};

/// Lumens per watt used to turn glTF's photometric units into radiometric ones.
pub(crate) const LM_PER_W: f32 = 683.0;

fn valid_color(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

/// A Blender light's emission: any finite colour. A negative strength is a light that takes
/// light away, as Cycles renders it (an artist's trick to darken a corner).
fn valid_emission(c: Vec3) -> bool {
    c.is_finite()
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

    /// The colour of a `TESELA_light`: `color`, or with a node tree that the add-on could not
    /// reduce (`graph`, with `base_color`, the light's own colour), `base_color` times what
    /// the tree emits when that is a constant (a Blackbody or an RGB node into the Emission:
    /// Cycles multiplies the light's strength by its shader's emission). A tree that varies
    /// over the light keeps `color` (the unlinked values) and its `node_warnings` are given.
    fn light_node_color(&mut self, ni: usize, t: &Value) -> Vec3 {
        let color = rgb(t, "color").unwrap_or(Vec3::ONE);
        let Some(g) = member(t, "graph").filter(|g| !g.is_null()) else {
            return color;
        };
        let name = member(self.raw_item("nodes", ni), "name")
            .and_then(Value::as_str)
            .map_or_else(|| format!("node {ni}"), str::to_string);
        let mut fallbacks = Vec::new();
        let emitted = crate::shading::Graph::from_json(g).ok().and_then(|graph| {
            // Images vary over the light (and are not resolved here).
            if graph.nodes.iter().any(|n| n.props.contains_key("image")) {
                return None;
            }
            let compiled = crate::shading::compile::compile(&graph, &name).ok()?;
            // A node the compiler stood in for (an IES texture, say) would fold into a wrong
            // constant: such a tree keeps the add-on's reading, and says why.
            if !compiled.warnings.is_empty() {
                fallbacks = compiled.warnings;
                return None;
            }
            compiled.program.constant_set().map(|set| set.emission)
        });
        match (emitted, rgb(t, "base_color")) {
            (Some(e), Some(base)) if valid_emission(e) => base * e,
            _ => {
                let notes = member(t, "node_warnings").and_then(Value::as_array);
                for m in notes.into_iter().flatten().filter_map(Value::as_str) {
                    self.warn_once(m.to_string());
                }
                for m in fallbacks {
                    self.warn_once(m);
                }
                color
            }
        }
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
        let color = self.light_node_color(ni, t);
        let f = |k: &str, d: f32| num(t, k).map(|v| v as f32).unwrap_or(d);
        let flag = |k: &str| member(t, k).and_then(Value::as_bool).unwrap_or(true);
        let visibility = LightVisibility {
            camera: flag("visible_camera"),
            diffuse: flag("visible_diffuse"),
            glossy: flag("visible_glossy"),
            transmission: flag("visible_transmission"),
            cast_shadow: flag("cast_shadow"),
            mis: flag("multiple_importance"),
        };
        let power = f("power", 0.0);
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z).try_normalize();
        let skip = |me: &mut Self, why: &str| {
            me.warn_once(format!("node {ni}: TESELA_light {ty}: {why} (skipped)"));
            Ok(())
        };
        let shape = match ty {
            "POINT" | "SPOT" => {
                let intensity = color * power / (4.0 * PI);
                if !valid_emission(intensity) {
                    return skip(self, "invalid color or power");
                }
                let mut radius = f("radius", 0.0);
                if !(radius.is_finite() && radius >= 0.0) {
                    self.warn_once(format!(
                        "node {ni}: TESELA_light {ty}: radius {radius} is not a length; \
                         rendered as radius 0"
                    ));
                    radius = 0.0;
                }
                let spot = if ty == "SPOT" {
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
                    Some((direction, spot_cone(world, cos_half, smooth)))
                } else {
                    None
                };
                LightShape::Point {
                    position,
                    intensity,
                    radius,
                    soft_falloff: member(t, "soft_falloff")
                        .and_then(Value::as_bool)
                        .unwrap_or(true),
                    spot,
                }
            }
            "SUN" => {
                let irradiance = color * f("strength", 1.0);
                let mut angle = f("angle", 0.0);
                let Some(direction) = direction else {
                    return skip(self, "degenerate direction");
                };
                if !valid_emission(irradiance) {
                    return skip(self, "invalid color or strength");
                }
                if !(angle.is_finite() && (0.0..=PI).contains(&angle)) {
                    let fallback = if angle.is_finite() {
                        angle.clamp(0.0, PI)
                    } else {
                        0.0
                    };
                    self.warn_once(format!(
                        "node {ni}: TESELA_light SUN: angle {angle} is outside [0, π]; \
                         rendered as {fallback}"
                    ));
                    angle = fallback;
                }
                LightShape::Sun {
                    direction,
                    irradiance,
                    angle,
                }
            }
            "AREA" => {
                let shape = member(t, "shape")
                    .and_then(Value::as_str)
                    .unwrap_or("SQUARE");
                let ellipse = matches!(shape, "DISK" | "ELLIPSE");
                let size = f("size", 1.0);
                let size_y = match shape {
                    "RECTANGLE" | "ELLIPSE" => f("size_y", size),
                    _ => size,
                };
                if !(size.is_finite() && size_y.is_finite() && size > 0.0 && size_y > 0.0) {
                    return skip(self, "invalid size");
                }
                let mut spread = f("spread", PI);
                if !(spread.is_finite() && (0.0..=PI).contains(&spread)) {
                    self.warn_once(format!(
                        "node {ni}: TESELA_light AREA: spread {spread} is outside [0, π]; \
                         rendered as π (no spread)"
                    ));
                    spread = PI;
                }
                // The node's transform places and sizes the light (its scale scales the size).
                let center = world.transform_point3(Vec3::ZERO);
                let wu = world.transform_vector3(Vec3::X);
                let wv = world.transform_vector3(Vec3::Y);
                let (lu, lv) = (wu.length(), wv.length());
                let axis_u = wu.try_normalize();
                let axis_v = axis_u.and_then(|u| (wv - u * wv.dot(u)).try_normalize());
                let (Some(axis_u), Some(axis_v)) = (axis_u, axis_v) else {
                    return skip(self, "degenerate transform");
                };
                let plane = axis_u.cross(axis_v);
                let facing = world.transform_vector3(-Vec3::Z);
                // The emitting side follows the node's -Z (mirrored nodes flip it); a flattened
                // node (zero Z scale) keeps the right-handed -Z.
                let normal = if facing.dot(plane) > 0.0 {
                    plane
                } else {
                    -plane
                };
                let (size_u, size_v) = (size * lu, size_y * lv);
                let area = size_u * size_v * if ellipse { PI / 4.0 } else { 1.0 };
                let radiance = color * power / (PI * area);
                if !(area > 0.0 && area.is_finite() && valid_emission(radiance)) {
                    return skip(self, "zero area, or invalid color or power");
                }
                LightShape::Area {
                    center,
                    axis_u,
                    axis_v,
                    normal,
                    size_u,
                    size_v,
                    ellipse,
                    radiance,
                    spread,
                }
            }
            other => {
                return skip(self, &format!("unknown type `{other}`"));
            }
        };
        let profile = self.light_profile(ni, ty, t, world);
        self.scene.lights.push(Light::Blender {
            shape,
            visibility,
            profile,
        });
        Ok(())
    }

    /// The IES profile of a `TESELA_light` (`ies`: `{"name", "data"}`, the LM-63 text).
    /// A profile that cannot be read is reported, naming the light and the file, and the
    /// light renders without it.
    fn light_profile(
        &mut self,
        ni: usize,
        ty: &str,
        t: &Value,
        world: Mat4,
    ) -> Option<LightProfile> {
        let ies = member(t, "ies").filter(|v| !v.is_null())?;
        let light = member(self.raw_item("nodes", ni), "name")
            .and_then(Value::as_str)
            .map_or_else(|| format!("node {ni}"), |n| format!("'{n}'"));
        let file = member(ies, "name")
            .and_then(Value::as_str)
            .unwrap_or("(unnamed)")
            .to_string();
        let profile = match member(ies, "data").and_then(Value::as_str) {
            _ if ty == "SUN" => Err("a sun's IES profile is not rendered".to_string()),
            Some(text) => IesProfile::parse(text),
            None => Err("`ies` has no `data` text".to_string()),
        };
        match profile {
            Ok(p) => Some(LightProfile {
                profile: Arc::new(p),
                to_local: Mat3::from_mat4(world).transpose(),
            }),
            Err(e) => {
                self.warn_once(format!(
                    "light {light}: IES profile '{file}': {e}; the light renders without it"
                ));
                None
            }
        }
    }
}

/// Cycles' spot falloff for a light whose node transform is `world`: scaled by the same
/// amount along its three axes (or not at all), the plain cone about its axis; else the cone
/// the scale stretches (Cycles takes the angle in the light's unscaled space).
fn spot_cone(world: Mat4, cos_half: f32, smooth: f32) -> SpotFalloff {
    let m = glam::Mat3::from_mat4(world);
    let s = Vec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
    let uniform = s.max_element() - s.min_element() <= 1e-4 * s.max_element();
    if uniform || s.min_element() <= 0.0 || !s.is_finite() {
        return SpotFalloff::Cycles { cos_half, smooth };
    }
    // Rows: the light's x and y axes and its beam axis (-z), each divided by its scale.
    let local = glam::Mat3::from_cols(
        m.x_axis / (s.x * s.x),
        m.y_axis / (s.y * s.y),
        -m.z_axis / (s.z * s.z),
    )
    .transpose();
    SpotFalloff::CyclesScaled {
        cos_half,
        smooth,
        local,
    }
}
