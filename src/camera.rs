//! Camera rays. Film coordinates are in pixels from the image's top-left corner, +x right,
//! +y down; the camera looks down its local -Z with +Y up (glTF).

use crate::scene::{Camera, Projection, Scene};
use glam::{Mat4, Vec2, Vec3};

/// A camera ready to generate rays for a `width × height` image.
#[derive(Clone, Debug)]
pub struct RayCamera {
    to_world: Mat4,
    width: f32,
    height: f32,
    projection: Projection,
    /// Half extents of the image plane at distance 1 (perspective) or in metres (orthographic).
    half: Vec2,
}

impl RayCamera {
    /// The scene's camera, or a default one framing the scene's bounding box from +Z.
    /// The image aspect comes from the resolution; the vertical field of view is kept.
    pub fn new(scene: &Scene, width: u32, height: u32) -> RayCamera {
        let cam = scene.camera.unwrap_or_else(|| default_camera(scene));
        let aspect = width as f32 / height as f32;
        let half = match cam.projection {
            Projection::Perspective { yfov } => {
                let t = (yfov * 0.5).tan();
                Vec2::new(t * aspect, t)
            }
            Projection::Orthographic { ymag } => Vec2::new(ymag * aspect, ymag),
        };
        RayCamera {
            to_world: cam.to_world,
            width: width as f32,
            height: height as f32,
            projection: cam.projection,
            half,
        }
    }

    /// World-space ray `(origin, unit direction)` through film position `film` (pixels).
    #[inline]
    pub fn ray(&self, film: Vec2) -> (Vec3, Vec3) {
        let x = (2.0 * film.x / self.width - 1.0) * self.half.x;
        let y = (1.0 - 2.0 * film.y / self.height) * self.half.y;
        match self.projection {
            Projection::Perspective { .. } => {
                let o = self.to_world.transform_point3(Vec3::ZERO);
                let d = self
                    .to_world
                    .transform_vector3(Vec3::new(x, y, -1.0))
                    .normalize();
                (o, d)
            }
            Projection::Orthographic { .. } => {
                let o = self.to_world.transform_point3(Vec3::new(x, y, 0.0));
                let d = self.to_world.transform_vector3(-Vec3::Z).normalize();
                (o, d)
            }
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
                to_world: Mat4::IDENTITY,
                aspect: None,
            }),
            ..Default::default()
        };
        let cam = RayCamera::new(&scene, 200, 100);
        let (o, d) = cam.ray(Vec2::new(100.0, 50.0));
        assert!(o.length() < 1e-6 && (d + Vec3::Z).length() < 1e-6);
        // Top edge centre is at 45° up; the right edge at atan(2) to the right (aspect 2).
        let (_, d) = cam.ray(Vec2::new(100.0, 0.0));
        assert!((d.y - d.z.abs()).abs() < 1e-5 && d.y > 0.0);
        let (_, d) = cam.ray(Vec2::new(200.0, 50.0));
        assert!((d.x / -d.z - 2.0).abs() < 1e-5);
    }
}
