//! A small z-buffer rasterizer for flat-shaded pictures of meshes (the paper's Fig. 5).
//!
//! Orthographic camera turned by a yaw about the vertical axis and a pitch about the horizontal,
//! framed on a fixed box so that every level of one mesh is drawn at the same place and scale.
//! Faces are lit from a light near the viewer on both sides, so a coarse level whose triangles
//! are not yet consistently oriented still reads correctly.

use crate::mesh::{Aabb, TriMesh};
use glam::{DMat3, DVec3};

/// Where the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Which axis points up in the model: 1 = y, 2 = z.
    pub up: usize,
    /// Turn about the up axis, degrees.
    pub yaw: f64,
    /// Tilt towards the viewer, degrees.
    pub pitch: f64,
}

impl Default for View {
    fn default() -> Self {
        View {
            up: 1,
            yaw: 0.0,
            pitch: 0.0,
        }
    }
}

/// An RGB picture.
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels, top row first.
    pub pixels: Vec<[u8; 3]>,
}

/// Draws `mesh` flat-shaded into a `width` × `height` picture framed on `frame`.
pub fn render(mesh: &TriMesh, frame: &Aabb, view: View, width: u32, height: u32) -> Picture {
    let centre = (frame.min + frame.max) * 0.5;
    // Model → camera: bring `up` to +y, then yaw, then pitch; the camera looks down −z.
    let to_y_up = if view.up == 2 {
        DMat3::from_rotation_x(-std::f64::consts::FRAC_PI_2)
    } else {
        DMat3::IDENTITY
    };
    let rotation = DMat3::from_rotation_x(view.pitch.to_radians())
        * DMat3::from_rotation_y(view.yaw.to_radians())
        * to_y_up;
    let radius = frame.diagonal() * 0.5;
    let scale = 0.96 * width.min(height) as f64 / (2.0 * radius.max(f64::MIN_POSITIVE));
    let project = |p: DVec3| {
        let q = rotation * (p - centre);
        DVec3::new(
            width as f64 * 0.5 + q.x * scale,
            height as f64 * 0.5 - q.y * scale,
            q.z,
        )
    };
    let screen: Vec<DVec3> = mesh.positions.iter().map(|&p| project(p)).collect();
    let mut depth = vec![f64::NEG_INFINITY; (width * height) as usize];
    let mut pixels = vec![[255u8; 3]; (width * height) as usize];
    let light = DVec3::new(-0.35, 0.45, 1.0).normalize();
    for f in &mesh.faces {
        let [a, b, c] = f.map(|v| screen[v as usize]);
        let world = mesh.corners(*f).map(|p| rotation * p);
        let normal = (world[1] - world[0]).cross(world[2] - world[0]);
        if normal.length_squared() == 0.0 {
            continue;
        }
        let shade = 0.18 + 0.82 * normal.normalize().dot(light).abs();
        let colour = [
            (shade * 200.0) as u8,
            (shade * 210.0) as u8,
            (shade * 235.0) as u8,
        ];
        let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        if area.abs() < 1e-12 {
            continue;
        }
        let x0 = a.x.min(b.x).min(c.x).floor().max(0.0) as u32;
        let x1 = (a.x.max(b.x).max(c.x).ceil() as i64).clamp(0, width as i64 - 1) as u32;
        let y0 = a.y.min(b.y).min(c.y).floor().max(0.0) as u32;
        let y1 = (a.y.max(b.y).max(c.y).ceil() as i64).clamp(0, height as i64 - 1) as u32;
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
                let w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * a.z + w1 * b.z + w2 * c.z;
                let i = (y * width + x) as usize;
                if z > depth[i] {
                    depth[i] = z;
                    pixels[i] = colour;
                }
            }
        }
    }
    Picture {
        width,
        height,
        pixels,
    }
}
