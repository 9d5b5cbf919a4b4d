//! Camera rays, generated as Cycles generates them (`kernel/camera/camera.h`, with the view
//! plane of `blender/camera.cpp`).
//!
//! Film coordinates are in pixels from the image's top-left corner, +x right, +y down. Camera
//! space looks down -Z with +Y up and +X right (glTF, and a Blender camera's local axes). The
//! image plane of a perspective camera is `z = -1`; with `u = film.x / width` and
//! `v = 1 - film.y / height` (`(0, 0)` bottom-left, as Cycles' raster), a pixel sits at
//! `x = (2u - 1) hx + 2 h s.x`, `y = (2v - 1) hy + 2 h s.y`, where `h` is the half extent of the
//! fitted dimension (`tan(fov/2)`, or metres for orthographic cameras), `(hx, hy)` the half
//! extents of the width and height and `s` the lens shift. Panoramic cameras map `(u + s.x,
//! v + s.y)` to a direction ([`Panorama`]).

use crate::sampling::{square_to_regular_polygon, square_to_uniform_disk};
use crate::scene::{Aperture, Camera, Panorama, Projection, Scene, SensorFit};
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::FRAC_PI_2;
use std::sync::atomic::{AtomicU32, Ordering};

/// One camera ray in world space: origin `o`, unit direction `d`, and the segment length
/// `tmax` before the far clip distance (infinite without one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRay {
    pub o: Vec3,
    pub d: Vec3,
    pub tmax: f32,
}

/// A point on the unit aperture as Cycles' `camera_sample_aperture` draws it from `u ∈ [0, 1)²`:
/// uniform on the unit disk (concentric map) when `blades < 3`, else uniform on the regular
/// `blades`-gon inscribed in the unit circle rotated by `rotation`
/// ([`square_to_regular_polygon`]); then `x` is divided by the anamorphic `ratio`. Uniform in
/// area over the resulting shape (density `ratio / (π or A_polygon)`).
#[inline]
pub fn sample_aperture(u: Vec2, blades: u32, rotation: f32, ratio: f32) -> Vec2 {
    let mut p = if blades >= 3 {
        square_to_regular_polygon(u, blades, rotation)
    } else {
        square_to_uniform_disk(u)
    };
    p.x /= ratio;
    p
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Perspective,
    Orthographic,
    /// With the sensor's width and height in mm (fisheye equisolid and polynomial).
    Panoramic(Panorama, Vec2),
}

/// A camera ready to generate rays for a `width × height` image.
#[derive(Clone, Debug)]
pub struct RayCamera {
    to_world: Mat4,
    /// The camera's position and view direction in world space.
    origin: Vec3,
    forward: Vec3,
    width: f32,
    height: f32,
    kind: Kind,
    /// Half extents of the image plane at distance 1 (perspective) or in metres (orthographic).
    half: Vec2,
    /// The lens shift on the image plane (perspective: at distance 1; orthographic: metres;
    /// panoramic: of `(u, v)`); `None` without shift.
    offset: Option<Vec2>,
    aperture: Option<Aperture>,
    clip_start: f32,
    clip_end: f32,
    /// The camera's camera-to-world over the shutter, when it moves.
    motion: Option<crate::motion::TransformMotion>,
    /// Whether anything in the scene moves: each camera path then draws a shutter time.
    scene_moves: bool,
}

impl RayCamera {
    /// The scene's camera, or a default one framing the scene's bounding box from +Z.
    /// The image aspect comes from the resolution; the fitted dimension's extent is kept
    /// (the vertical field of view for glTF cameras).
    pub fn new(scene: &Scene, width: u32, height: u32) -> RayCamera {
        let cam = scene.camera.unwrap_or_else(|| default_camera(scene));
        let aspect = width as f32 * cam.pixel_aspect / height as f32;
        let horizontal = cam.fit.is_horizontal(aspect);
        // Half extents of the image for a fitted half extent `h`.
        let extents = |h: f32| {
            if horizontal {
                Vec2::new(h, h / aspect)
            } else {
                Vec2::new(h * aspect, h)
            }
        };
        let (kind, fitted) = match cam.projection {
            Projection::Perspective { yfov } => (Kind::Perspective, (yfov * 0.5).tan()),
            Projection::Orthographic { ymag } => (Kind::Orthographic, ymag),
            Projection::Panoramic(p) => {
                let sensor = match p {
                    Panorama::FisheyeEquisolid { sensor, .. }
                    | Panorama::FisheyeLensPolynomial { sensor, .. } => sensor,
                    _ => 1.0,
                };
                // Cycles' sensor size: the fitted dimension's, the other one by the aspect.
                let (w, h) = (width as f32 * cam.pixel_aspect, height as f32);
                let s = if horizontal {
                    Vec2::new(sensor, sensor * h / w)
                } else {
                    Vec2::new(sensor * w / h, sensor)
                };
                (Kind::Panoramic(p, s), 0.5)
            }
        };
        let offset = (cam.shift != Vec2::ZERO).then(|| match kind {
            Kind::Panoramic(..) => cam.shift,
            _ => 2.0 * fitted * cam.shift,
        });
        RayCamera {
            to_world: cam.to_world,
            origin: cam.to_world.transform_point3(Vec3::ZERO),
            forward: cam.to_world.transform_vector3(-Vec3::Z).normalize(),
            width: width as f32,
            height: height as f32,
            kind,
            half: extents(fitted),
            offset,
            aperture: cam.aperture,
            clip_start: cam.clip_start,
            clip_end: cam.clip_end,
            motion: scene.camera.and(scene.camera_motion.clone()),
            scene_moves: scene.has_motion(),
        }
    }

    /// Whether camera paths need a shutter time (something in the scene moves): the caller
    /// draws one only then, so scenes without motion consume no random number for it.
    #[inline]
    pub fn needs_time(&self) -> bool {
        self.scene_moves
    }

    /// [`RayCamera::ray`] at shutter time `time`: from where a moving camera is then
    /// (its transform interpolated as [`crate::motion`] describes).
    #[inline]
    pub fn ray_at(&self, film: Vec2, lens: Vec2, time: f32) -> Option<CameraRay> {
        let Some(m) = &self.motion else {
            return self.ray(film, lens);
        };
        let to_world = m.at(time);
        let moved = RayCamera {
            to_world,
            origin: to_world.transform_point3(Vec3::ZERO),
            forward: to_world.transform_vector3(-Vec3::Z).normalize(),
            motion: None,
            ..self.clone()
        };
        moved.ray(film, lens)
    }

    /// The camera's depth of world point `p`, as Cycles' Depth pass measures it: along the
    /// view axis (metres in front of the camera) for perspective and orthographic cameras,
    /// the distance from the camera for panoramic ones.
    #[inline]
    pub fn z_depth(&self, p: Vec3) -> f32 {
        match self.kind {
            Kind::Panoramic(..) => (p - self.origin).length(),
            _ => (p - self.origin).dot(self.forward),
        }
    }

    /// The camera distance of `p` the Mist pass uses (Cycles' `camera_distance`): along the
    /// view axis for orthographic cameras, the distance from the camera otherwise.
    #[inline]
    pub fn mist_distance(&self, p: Vec3) -> f32 {
        match self.kind {
            Kind::Orthographic => (p - self.origin).dot(self.forward),
            _ => (p - self.origin).length(),
        }
    }

    /// The world direction `v` in Cycles' camera space (x right, y up, z along the view),
    /// where the denoiser's normal feature lives.
    #[inline]
    pub fn to_camera_direction(&self, v: Vec3) -> Vec3 {
        let x = self.to_world.x_axis.truncate().normalize_or_zero();
        let y = self.to_world.y_axis.truncate().normalize_or_zero();
        Vec3::new(v.dot(x), v.dot(y), v.dot(self.forward))
    }

    /// Whether rays need a lens sample (depth of field): the caller draws one only then, so
    /// a pinhole camera consumes no random numbers for it.
    #[inline]
    pub fn has_lens(&self) -> bool {
        self.aperture.is_some()
    }

    /// The point on the lens (camera space, on the plane z = 0, metres) for the sample `u`.
    #[inline]
    fn lens_point(a: &Aperture, u: Vec2) -> Vec3 {
        (sample_aperture(u, a.blades, a.rotation, a.ratio) * a.radius).extend(0.0)
    }

    /// The image-plane position of film position `film` (pixels), shift included.
    #[inline]
    fn plane(&self, film: Vec2) -> Vec2 {
        let x = (2.0 * film.x / self.width - 1.0) * self.half.x;
        let y = (1.0 - 2.0 * film.y / self.height) * self.half.y;
        match self.offset {
            Some(o) => Vec2::new(x + o.x, y + o.y),
            None => Vec2::new(x, y),
        }
    }

    /// The world-space ray through film position `film` (pixels); `lens` is the lens sample in
    /// `[0, 1)²`, read only when [`RayCamera::has_lens`]. `None` where the image shows nothing
    /// (outside a fisheye's circle): that sample is black.
    #[inline]
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Option<CameraRay> {
        match self.kind {
            Kind::Perspective => {
                let p = self.plane(film);
                // The pinhole ray's direction, and the lens point aiming where it meets the
                // plane in focus (`z = -focus_distance`).
                let pin = Vec3::new(p.x, p.y, -1.0);
                let (o, d) = match &self.aperture {
                    None => (
                        self.origin,
                        self.to_world.transform_vector3(pin).normalize(),
                    ),
                    Some(a) => {
                        let l = Self::lens_point(a, lens);
                        let d = pin * a.focus_distance - l;
                        (
                            self.to_world.transform_point3(l),
                            self.to_world.transform_vector3(d).normalize(),
                        )
                    }
                };
                // Cycles clips along the ray by the pinhole ray's length per unit depth.
                Some(self.clipped(o, d, pin.length()))
            }
            Kind::Orthographic => {
                let p = self.plane(film).extend(0.0);
                match &self.aperture {
                    None => {
                        let o = self.to_world.transform_point3(p);
                        Some(self.clipped(o, self.forward, 1.0))
                    }
                    Some(a) => {
                        // Every ray of the pixel meets its pinhole ray at the plane in focus;
                        // it starts where it crosses the near plane.
                        let l = Self::lens_point(a, lens);
                        let d = (Vec3::new(0.0, 0.0, -a.focus_distance) - l).normalize();
                        let q = p + l + d * (self.clip_start / -d.z);
                        Some(CameraRay {
                            o: self.to_world.transform_point3(q),
                            d: self.to_world.transform_vector3(d).normalize(),
                            tmax: self.clip_end - self.clip_start,
                        })
                    }
                }
            }
            Kind::Panoramic(pano, sensor) => {
                let mut u = film.x / self.width;
                let mut v = 1.0 - film.y / self.height;
                if let Some(o) = self.offset {
                    u += o.x;
                    v += o.y;
                }
                let dir = panorama_direction(&pano, u, v, sensor)?;
                let (p, dir) = match &self.aperture {
                    None => (Vec3::ZERO, dir),
                    Some(a) => {
                        // In panorama space, as Cycles: the lens is the disk perpendicular
                        // to the pinhole ray, which it meets on the sphere in focus.
                        let l = Self::lens_point(a, lens);
                        let f = dir.normalize();
                        let eu = (Vec3::X - f.x * f).try_normalize().unwrap_or(Vec3::Y);
                        let ev = f.cross(eu).normalize();
                        let p = eu * l.x + ev * l.y;
                        (p, f * a.focus_distance - p)
                    }
                };
                let to_camera = |w: Vec3| match pano {
                    Panorama::Mirrorball => Vec3::new(w.x, w.z, w.y),
                    _ => Vec3::new(-w.y, w.z, -w.x),
                };
                let o = self.to_world.transform_point3(to_camera(p));
                let d = self.to_world.transform_vector3(to_camera(dir)).normalize();
                if !d.is_finite() {
                    return None;
                }
                Some(self.clipped(o, d, 1.0))
            }
        }
    }

    /// The ray from `o` along `d` clipped to `[clip_start, clip_end] · scale` (a ray with no
    /// near clip keeps its origin exactly).
    #[inline]
    fn clipped(&self, o: Vec3, d: Vec3, scale: f32) -> CameraRay {
        let o = if self.clip_start > 0.0 {
            o + d * (self.clip_start * scale)
        } else {
            o
        };
        CameraRay {
            o,
            d,
            tmax: (self.clip_end - self.clip_start) * scale,
        }
    }
}

/// glTF's world (Y up) to Blender's (Z up): `(x, y, z) -> (x, -z, y)`.
pub const GLTF_TO_BLENDER: Mat4 = Mat4::from_cols(
    glam::Vec4::X,
    glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
    glam::Vec4::new(0.0, -1.0, 0.0, 0.0),
    glam::Vec4::W,
);

/// Blender's Window texture coordinates of world points (Cycles' `camera_world_to_ndc`): the
/// camera frame's `[0, 1]²`, `(0, 0)` at its bottom-left corner, lens shift included, `z = 0`.
/// The frame's aspect follows the resolution of the latest render
/// ([`WindowMap::set_resolution`]), which is why it is atomic: renders share the scene.
#[derive(Debug)]
pub struct WindowMap {
    world_to_camera: Mat4,
    /// `Some(perspective)` for perspective and orthographic cameras; `None` for panoramas,
    /// whose Window coordinates Tesela does not compute.
    perspective: Option<bool>,
    /// `tan(yfov / 2)` (perspective) or the half height in metres (orthographic) of the
    /// fitted dimension.
    fitted: f32,
    fit: SensorFit,
    shift: Vec2,
    pixel_aspect: f32,
    width: AtomicU32,
    height: AtomicU32,
}

/// Window coordinates where there is no camera (emitters' set-up, tests): `(0, 0, 0)`.
pub static NO_WINDOW: WindowMap = WindowMap::none();

impl WindowMap {
    /// No camera: every point reads `(0, 0, 0)`.
    pub const fn none() -> WindowMap {
        WindowMap {
            world_to_camera: Mat4::IDENTITY,
            perspective: None,
            fitted: 1.0,
            fit: SensorFit::Auto,
            shift: Vec2::ZERO,
            pixel_aspect: 1.0,
            width: AtomicU32::new(1),
            height: AtomicU32::new(1),
        }
    }

    /// The scene's camera (or the default one), for a square frame until a resolution is set.
    pub fn new(scene: &Scene) -> WindowMap {
        let cam = scene.camera.unwrap_or_else(|| default_camera(scene));
        let (perspective, fitted) = match cam.projection {
            Projection::Perspective { yfov } => (Some(true), (yfov * 0.5).tan()),
            Projection::Orthographic { ymag } => (Some(false), ymag),
            Projection::Panoramic(_) => (None, 1.0),
        };
        // Shading points are in Blender's world (Z up); the camera is in glTF's (Y up).
        WindowMap {
            world_to_camera: (GLTF_TO_BLENDER * cam.to_world).inverse(),
            perspective,
            fitted,
            fit: cam.fit,
            shift: cam.shift,
            pixel_aspect: cam.pixel_aspect,
            width: AtomicU32::new(1),
            height: AtomicU32::new(1),
        }
    }

    /// Whether the camera's Window coordinates are computed (not a panorama).
    pub fn supported(&self) -> bool {
        self.perspective.is_some()
    }

    pub fn resolution(&self) -> (u32, u32) {
        (
            self.width.load(Ordering::Relaxed),
            self.height.load(Ordering::Relaxed),
        )
    }

    pub fn set_resolution(&self, width: u32, height: u32) {
        self.width.store(width.max(1), Ordering::Relaxed);
        self.height.store(height.max(1), Ordering::Relaxed);
    }

    /// The Window coordinates of point `p` (Blender's world space); `(0, 0, 0)` where they are not finite (in
    /// the camera's plane) or not computed.
    #[inline]
    pub fn window(&self, p: Vec3) -> Vec3 {
        let Some(perspective) = self.perspective else {
            return Vec3::ZERO;
        };
        let (w, h) = (
            self.width.load(Ordering::Relaxed),
            self.height.load(Ordering::Relaxed),
        );
        let aspect = w as f32 * self.pixel_aspect / h as f32;
        let f = self.fitted;
        let half = if self.fit.is_horizontal(aspect) {
            Vec2::new(f, f / aspect)
        } else {
            Vec2::new(f * aspect, f)
        };
        let q = self.world_to_camera.transform_point3(p);
        let plane = if perspective {
            Vec2::new(q.x, q.y) / -q.z
        } else {
            Vec2::new(q.x, q.y)
        };
        let ndc = ((plane - 2.0 * f * self.shift) / half + Vec2::ONE) * 0.5;
        if ndc.is_finite() {
            ndc.extend(0.0)
        } else {
            Vec3::ZERO
        }
    }
}

/// Cycles' `fisheye_to_direction`: angle `theta` from the view axis (+X), in the azimuth of
/// the image offset `(u, v)` of length `r`.
#[inline]
fn fisheye_to_direction(theta: f32, u: f32, v: f32, r: f32) -> Vec3 {
    let c = if r != 0.0 { u / r } else { 0.0 };
    let mut phi = c.clamp(-1.0, 1.0).acos();
    if v < 0.0 {
        phi = -phi;
    }
    let (st, ct) = theta.sin_cos();
    Vec3::new(ct, -phi.cos() * st, phi.sin() * st)
}

/// The (not necessarily unit) direction, in panorama space (+X forward, +Y left, +Z up), that
/// image position `(u, v)` (`[0, 1]²` from the bottom-left corner) sees; `None` outside the
/// projection's image. `sensor`: the sensor's width and height in mm.
pub fn panorama_direction(p: &Panorama, u: f32, v: f32, sensor: Vec2) -> Option<Vec3> {
    match *p {
        Panorama::Equirectangular {
            latitude_min,
            latitude_max,
            longitude_min,
            longitude_max,
        } => {
            let phi = (longitude_min - longitude_max) * u - longitude_min;
            let theta = (latitude_min - latitude_max) * v - latitude_min + FRAC_PI_2;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            Some(Vec3::new(st * cp, st * sp, ct))
        }
        Panorama::FisheyeEquidistant { fov } => {
            let (x, y) = ((u - 0.5) * 2.0, (v - 0.5) * 2.0);
            let r = (x * x + y * y).sqrt();
            if r > 1.0 {
                return None;
            }
            Some(fisheye_to_direction(r * fov * 0.5, x, y, r))
        }
        Panorama::FisheyeEquisolid { fov, lens, .. } => {
            let (x, y) = ((u - 0.5) * sensor.x, (v - 0.5) * sensor.y);
            let r = (x * x + y * y).sqrt();
            if r > 2.0 * lens * (fov * 0.25).sin() {
                return None;
            }
            let theta = 2.0 * (r / (2.0 * lens)).min(1.0).asin();
            Some(fisheye_to_direction(theta, x, y, r))
        }
        Panorama::FisheyeLensPolynomial { fov, k, .. } => {
            let (x, y) = ((u - 0.5) * sensor.x, (v - 0.5) * sensor.y);
            let r = (x * x + y * y).sqrt();
            let theta = -(k[0] + r * (k[1] + r * (k[2] + r * (k[3] + r * k[4]))));
            if theta.abs() > 0.5 * fov {
                return None;
            }
            Some(fisheye_to_direction(theta, x, y, r))
        }
        Panorama::Mirrorball => {
            let (x, z) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            if x * x + z * z > 1.0 {
                return None;
            }
            let n = Vec3::new(x, -(1.0 - x * x - z * z).max(0.0).sqrt(), z);
            // The view ray (0, 1, 0) reflected about the ball's normal.
            let i = Vec3::new(0.0, -1.0, 0.0);
            Some(2.0 * n.dot(i) * n - i)
        }
        Panorama::EquiangularCubemapFace => {
            let a = ((0.5 - u) * FRAC_PI_2).tan();
            let b = ((v - 0.5) * FRAC_PI_2).tan();
            Some(Vec3::new(1.0, a, b).normalize())
        }
        Panorama::CentralCylindrical {
            u_min,
            u_max,
            v_min,
            v_max,
        } => {
            let theta = -u_min + u * (u_min - u_max);
            let z = v_min + v * (v_max - v_min);
            Some(Vec3::new(theta.cos(), theta.sin(), z))
        }
    }
}

/// A perspective camera (40° vertical field of view) on the +Z side of the scene's bounding
/// sphere, looking at its centre, far enough to see all of it.
pub fn default_camera(scene: &Scene) -> Camera {
    let yfov = 40f32.to_radians();
    let (center, radius) = match scene.bounds() {
        Some((lo, hi)) => ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-3)),
        None => (Vec3::ZERO, 1.0),
    };
    let dist = radius / (yfov * 0.5).sin() * 1.05;
    Camera {
        projection: Projection::Perspective { yfov },
        to_world: Mat4::from_translation(center + Vec3::Z * dist),
        aspect: None,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_down_minus_z_and_corners_match_fov() {
        let scene = Scene {
            camera: Some(Camera {
                projection: Projection::Perspective {
                    yfov: 90f32.to_radians(),
                },
                ..Default::default()
            }),
            ..Default::default()
        };
        let cam = RayCamera::new(&scene, 200, 100);
        let r = cam.ray(Vec2::new(100.0, 50.0), Vec2::ZERO).unwrap();
        assert!(r.o.length() < 1e-6 && (r.d + Vec3::Z).length() < 1e-6);
        assert_eq!(r.tmax, f32::INFINITY);
        // Top edge centre is at 45° up; the right edge at atan(2) to the right (aspect 2).
        let d = cam.ray(Vec2::new(100.0, 0.0), Vec2::ZERO).unwrap().d;
        assert!((d.y - d.z.abs()).abs() < 1e-5 && d.y > 0.0);
        let d = cam.ray(Vec2::new(200.0, 50.0), Vec2::ZERO).unwrap().d;
        assert!((d.x / -d.z - 2.0).abs() < 1e-5);
    }
}
