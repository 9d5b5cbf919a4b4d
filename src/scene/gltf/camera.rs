//! Cameras: the glTF camera of a node, replaced by its `TESELA_camera` extension (Blender's
//! native camera data, `docs/extensions.md`) when the node has one.
//!
//! Bad `TESELA_camera` values never fail the load: each is reported once and replaced by a
//! fallback (Blender's default for that field, a pinhole for an unusable depth of field, the
//! glTF camera for an unusable perspective or orthographic projection).

use glam::{Mat4, Vec2};
use serde_json::Value;
use std::f32::consts::{FRAC_PI_2, PI};

use super::{Loader, extension, invalid, member, orthonormalize};
use crate::scene::error::LoadError;
use crate::scene::{Aperture, Camera, Panorama, Projection, SensorFit};
use ::gltf::json;

/// Reads `TESELA_camera` fields, collecting a message for every value it cannot use.
struct Fields<'v> {
    v: &'v Value,
    /// Prefix of the messages: `camera 0 (node 3): TESELA_camera`.
    at: String,
    warnings: Vec<String>,
}

impl<'v> Fields<'v> {
    fn warn(&mut self, msg: String) {
        self.warnings.push(format!("{}{msg}", self.at));
    }

    /// `key` as a finite number; `default` when absent, or (reported) when it is not one.
    fn num(&mut self, key: &str, default: f32) -> f32 {
        match member(self.v, key) {
            None => default,
            Some(x) => match x.as_f64().map(|f| f as f32).filter(|f| f.is_finite()) {
                Some(f) => f,
                None => {
                    self.warn(format!(
                        ".{key} = {x} is not a finite number: {default} used"
                    ));
                    default
                }
            },
        }
    }

    /// `key` as a positive finite number (`default` when absent); `None` (reported, saying
    /// `fallback`) when it is not one.
    fn positive(&mut self, key: &str, default: f32, fallback: &str) -> Option<f32> {
        let Some(x) = member(self.v, key) else {
            return Some(default);
        };
        match x.as_f64().map(|f| f as f32) {
            Some(f) if f.is_finite() && f > 0.0 => Some(f),
            _ => {
                self.warn(format!(".{key} = {x} is not a positive number: {fallback}"));
                None
            }
        }
    }

    /// `key` as one of `allowed` (`default` when absent); `None` (reported) otherwise.
    fn choice(
        &mut self,
        key: &str,
        default: &'static str,
        allowed: &[&'static str],
    ) -> Option<&'static str> {
        let Some(x) = member(self.v, key) else {
            return Some(default);
        };
        let found = x
            .as_str()
            .and_then(|s| allowed.iter().find(|a| **a == s).copied());
        if found.is_none() {
            self.warn(format!(".{key} = {x} is not one of {}", allowed.join(", ")));
        }
        found
    }
}

impl<'a> Loader<'a> {
    /// The camera of node `ni` (glTF camera `ci`, world transform `world`).
    pub(super) fn camera(
        &mut self,
        ci: usize,
        ni: usize,
        world: Mat4,
    ) -> Result<Camera, LoadError> {
        let cam = self.root.cameras.get(ci).ok_or_else(|| {
            invalid(format!(
                "node {ni}: camera {ci} does not exist (the file has {})",
                self.root.cameras.len()
            ))
        })?;
        use json::camera::Type as T;
        use json::validation::Checked;
        let (projection, aspect) = match (&cam.type_, &cam.perspective, &cam.orthographic) {
            (Checked::Valid(T::Perspective), Some(p), _) => {
                let y = p.yfov;
                if !(y.is_finite() && y > 0.0 && y < PI) {
                    return Err(invalid(format!(
                        "camera {ci}: perspective yfov {y} is not in (0, pi)"
                    )));
                }
                let aspect = p.aspect_ratio.filter(|a| a.is_finite() && *a > 0.0);
                (Projection::Perspective { yfov: y }, aspect)
            }
            (Checked::Valid(T::Orthographic), _, Some(o)) => {
                let m = o.ymag.abs();
                if !(m.is_finite() && m > 0.0) {
                    return Err(invalid(format!(
                        "camera {ci}: orthographic ymag {} is zero or not finite",
                        o.ymag
                    )));
                }
                let x = o.xmag.abs();
                let aspect = (x.is_finite() && x > 0.0).then_some(x / m);
                (Projection::Orthographic { ymag: m }, aspect)
            }
            (Checked::Valid(T::Perspective), None, _) => {
                return Err(invalid(format!(
                    "camera {ci}: type perspective without a `perspective` object"
                )));
            }
            (Checked::Valid(T::Orthographic), _, None) => {
                return Err(invalid(format!(
                    "camera {ci}: type orthographic without an `orthographic` object"
                )));
            }
            (Checked::Invalid, _, _) => {
                return Err(invalid(format!("camera {ci}: invalid type")));
            }
        };
        let to_world = orthonormalize(world).ok_or_else(|| {
            invalid(format!(
                "node {ni}: camera transform is degenerate (zero scale)"
            ))
        })?;
        // znear/zfar clip as Blender's importer makes them clip_start/clip_end: the rays
        // start at the plane znear in front of the camera and end at the plane zfar.
        let (znear, zfar) = match (&projection, &cam.perspective, &cam.orthographic) {
            (Projection::Perspective { .. }, Some(p), _) => (p.znear, p.zfar),
            (Projection::Orthographic { .. }, _, Some(o)) => (o.znear, Some(o.zfar)),
            _ => (0.0, None),
        };
        let clip_start = if znear.is_finite() && znear > 0.0 {
            znear
        } else {
            0.0
        };
        let clip_end = zfar
            .filter(|z| z.is_finite() && *z > clip_start)
            .unwrap_or(f32::INFINITY);
        let gltf = Camera {
            projection,
            to_world,
            aspect,
            clip_start,
            clip_end,
            ..Default::default()
        };
        let Some(ext) = extension(self.raw_item("nodes", ni), "TESELA_camera") else {
            return Ok(gltf);
        };
        let mut f = Fields {
            v: ext,
            at: format!("camera {ci} (node {ni}): TESELA_camera"),
            warnings: Vec::new(),
        };
        let cam = blender_camera(&mut f, gltf);
        for w in f.warnings {
            self.warn_once(w);
        }
        Ok(cam)
    }
}

/// The camera `TESELA_camera` (`f`) describes, on the node's transform; `gltf` is the node's
/// glTF camera, the fallback for what the extension cannot say.
fn blender_camera(f: &mut Fields, gltf: Camera) -> Camera {
    const TYPES: &[&str] = &["PERSP", "ORTHO", "PANO", "CUSTOM"];
    let Some(ty) = f.choice("type", "PERSP", TYPES) else {
        f.warn(": the glTF camera is rendered instead".into());
        return gltf;
    };
    if ty == "CUSTOM" {
        f.warn(
            ".type CUSTOM (an OSL camera) is not supported: the glTF camera is rendered instead"
                .into(),
        );
        return gltf;
    }
    let fit = match f.choice("sensor_fit", "AUTO", &["AUTO", "HORIZONTAL", "VERTICAL"]) {
        Some("HORIZONTAL") => SensorFit::Horizontal,
        Some("VERTICAL") => SensorFit::Vertical,
        _ => SensorFit::Auto,
    };
    // The sensor size across the fitted dimension (AUTO uses the width, as Blender).
    let sensor_key = if fit == SensorFit::Vertical {
        ("sensor_height", 24.0)
    } else {
        ("sensor_width", 36.0)
    };
    let lens = f.positive("lens", 50.0, "the glTF camera's field of view is used");
    let mut cam = Camera { fit, ..gltf };
    match ty {
        "PERSP" => {
            let sensor = f.positive(
                sensor_key.0,
                sensor_key.1,
                "the glTF camera's field of view is used",
            );
            match (lens, sensor) {
                (Some(lens), Some(sensor)) => {
                    let yfov = 2.0 * (sensor / (2.0 * lens)).atan();
                    if yfov > 0.0 && yfov < PI {
                        cam.projection = Projection::Perspective { yfov };
                    } else {
                        f.warn(format!(": lens {lens} mm on a {sensor} mm sensor gives no usable field of view: the glTF camera's is used"));
                        cam.fit = gltf.fit;
                    }
                }
                _ => cam.fit = gltf.fit,
            }
        }
        "ORTHO" => match f.positive("ortho_scale", 6.0, "the glTF camera's extent is used") {
            Some(s) => cam.projection = Projection::Orthographic { ymag: 0.5 * s },
            None => cam.fit = gltf.fit,
        },
        _ => cam.projection = Projection::Panoramic(panorama(f, sensor_key)),
    }
    cam.shift = Vec2::new(f.num("shift_x", 0.0), f.num("shift_y", 0.0));
    cam.pixel_aspect = f
        .positive("pixel_aspect", 1.0, "square pixels are used")
        .unwrap_or(1.0);
    let start = f.num("clip_start", 0.0);
    cam.clip_start = if start >= 0.0 {
        start
    } else {
        f.warn(format!(".clip_start = {start} is negative: 0 used"));
        0.0
    };
    if member(f.v, "clip_end").is_some() {
        let end = f.num("clip_end", f32::INFINITY);
        if end > cam.clip_start {
            cam.clip_end = end;
        } else {
            f.warn(format!(
                ".clip_end = {end} is not beyond clip_start {}: no far clipping",
                cam.clip_start
            ));
        }
    }
    cam.aperture = aperture(f, ty, lens.unwrap_or(50.0));
    cam
}

/// The panoramic projection of `TESELA_camera` (`sensor`: the key and default of the sensor
/// size across the fitted dimension).
fn panorama(f: &mut Fields, sensor: (&str, f32)) -> Panorama {
    const TYPES: &[&str] = &[
        "EQUIRECTANGULAR",
        "EQUIANGULAR_CUBEMAP_FACE",
        "MIRRORBALL",
        "FISHEYE_EQUIDISTANT",
        "FISHEYE_EQUISOLID",
        "FISHEYE_LENS_POLYNOMIAL",
        "CENTRAL_CYLINDRICAL",
    ];
    let ty = f
        .choice("panorama_type", "FISHEYE_EQUISOLID", TYPES)
        .unwrap_or_else(|| {
            f.warn(": rendered as FISHEYE_EQUISOLID (as Cycles does)".into());
            "FISHEYE_EQUISOLID"
        });
    match ty {
        "EQUIRECTANGULAR" => Panorama::Equirectangular {
            latitude_min: f.num("latitude_min", -FRAC_PI_2),
            latitude_max: f.num("latitude_max", FRAC_PI_2),
            longitude_min: f.num("longitude_min", -PI),
            longitude_max: f.num("longitude_max", PI),
        },
        "EQUIANGULAR_CUBEMAP_FACE" => Panorama::EquiangularCubemapFace,
        "MIRRORBALL" => Panorama::Mirrorball,
        "FISHEYE_EQUIDISTANT" => Panorama::FisheyeEquidistant {
            fov: fisheye_fov(f),
        },
        "FISHEYE_LENS_POLYNOMIAL" => {
            let fov = fisheye_fov(f);
            let k = ["k0", "k1", "k2", "k3", "k4"]
                .map(|k| f.num(&format!("fisheye_polynomial_{k}"), 0.0));
            let sensor = f
                .positive(sensor.0, sensor.1, "the default used")
                .unwrap_or(sensor.1);
            Panorama::FisheyeLensPolynomial { fov, sensor, k }
        }
        "CENTRAL_CYLINDRICAL" => {
            let r = f
                .positive("central_cylindrical_radius", 1.0, "1 used")
                .unwrap_or(1.0);
            Panorama::CentralCylindrical {
                u_min: f.num("central_cylindrical_range_u_min", -PI),
                u_max: f.num("central_cylindrical_range_u_max", PI),
                v_min: f.num("central_cylindrical_range_v_min", -1.0) / r,
                v_max: f.num("central_cylindrical_range_v_max", 1.0) / r,
            }
        }
        _ => {
            let fov = fisheye_fov(f);
            let lens = f
                .positive("fisheye_lens", 10.5, "10.5 mm used")
                .unwrap_or(10.5);
            let sensor = f
                .positive(sensor.0, sensor.1, "the default used")
                .unwrap_or(sensor.1);
            Panorama::FisheyeEquisolid { fov, lens, sensor }
        }
    }
}

/// `fisheye_fov` (radians), 180° when absent or unusable.
fn fisheye_fov(f: &mut Fields) -> f32 {
    f.positive("fisheye_fov", PI, "180° used").unwrap_or(PI)
}

/// The depth of field of `TESELA_camera.dof` for a camera of type `ty` with focal length
/// `lens` (mm); `None` (a pinhole) without one, or (reported) when it is unusable.
fn aperture(f: &mut Fields, ty: &str, lens: f32) -> Option<Aperture> {
    let dof = member(f.v, "dof")?;
    if !dof.is_object() {
        f.warn(".dof is not an object: no depth of field".into());
        return None;
    }
    let mut d = Fields {
        v: dof,
        at: format!("{}.dof", f.at),
        warnings: Vec::new(),
    };
    let a = dof_fields(&mut d, ty, lens);
    f.warnings.append(&mut d.warnings);
    a
}

fn dof_fields(d: &mut Fields, ty: &str, lens: f32) -> Option<Aperture> {
    if member(d.v, "use_dof").and_then(Value::as_bool) == Some(false) {
        return None;
    }
    const PINHOLE: &str = "rendered without depth of field (a pinhole)";
    let fstop = d.positive("aperture_fstop", 2.8, PINHOLE)?;
    let focus = d.num("focus_distance", 10.0);
    if focus < 0.0 {
        d.warn(format!(".focus_distance = {focus} is negative: {PINHOLE}"));
        return None;
    }
    // Cycles' lens radius: the focal length over twice the f-number (orthographic cameras
    // have no focal length: 1 m over it).
    let focal = if ty == "ORTHO" { 1.0 } else { lens * 1e-3 };
    let radius = focal / (2.0 * fstop);
    if !(radius.is_finite() && radius > 0.0) {
        d.warn(format!(
            ".aperture_fstop = {fstop} gives no usable aperture: {PINHOLE}"
        ));
        return None;
    }
    let blades = d.num("aperture_blades", 0.0).round();
    let blades = if blades >= 3.0 {
        blades.min(1e6) as u32
    } else {
        if blades != 0.0 {
            d.warn(format!(
                ".aperture_blades = {blades} makes no polygon: a round aperture (as Cycles)"
            ));
        }
        0
    };
    let ratio = d
        .positive("aperture_ratio", 1.0, "1 used (no anamorphic bokeh)")
        .unwrap_or(1.0);
    Some(Aperture {
        radius,
        // Cycles' floor.
        focus_distance: focus.max(1e-5),
        blades,
        rotation: d.num("aperture_rotation", 0.0),
        ratio,
    })
}
