//! A small z-buffer rasterizer for flat-shaded pictures of meshes (the paper's Fig. 5).
//!
//! Orthographic camera turned by a yaw about the vertical axis and a pitch about the horizontal,
//! framed on a fixed box so that every level of one mesh is drawn at the same place and scale.
//! Faces are lit from a light near the viewer on both sides, so a coarse level whose triangles
//! are not yet consistently oriented still reads correctly.

use glam::{DMat3, DVec2, DVec3};
use meshcodec::mesh::{Aabb, TriMesh};

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
    // Model → camera: bring `up` to +y, then yaw, then pitch; the camera looks down −z.
    let (rotation, project) = orthographic(frame, view, width, height);
    let screen: Vec<DVec3> = mesh.positions.iter().map(|&p| project(p)).collect();
    rasterize(mesh, &screen, |p| rotation * p, width, height, flat)
}

/// Checker squares across the unit uv square in [`render_textured`].
pub const CHECKER_SQUARES: f64 = 32.0;

/// Draws `mesh` as [`render`] does, textured with a checker through `corner_uvs` (one uv per
/// face corner, face by face): each uv chart shows its squares, and a seam pulled apart or a
/// chart distorted breaks them.
pub fn render_textured(
    mesh: &TriMesh,
    corner_uvs: &[[DVec2; 3]],
    frame: &Aabb,
    view: View,
    width: u32,
    height: u32,
) -> Picture {
    let (rotation, project) = orthographic(frame, view, width, height);
    let screen: Vec<DVec3> = mesh.positions.iter().map(|&p| project(p)).collect();
    let checker = |face: usize, w: [f64; 3], shade: f64| {
        let Some(t) = corner_uvs.get(face) else {
            return flat(face, w, shade);
        };
        let uv = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        let square = (uv * CHECKER_SQUARES).floor();
        let dark = (square.x + square.y).rem_euclid(2.0) >= 1.0;
        let base = if dark {
            [60.0, 70.0, 150.0]
        } else {
            [245.0, 225.0, 150.0]
        };
        base.map(|c| (c * shade) as u8)
    };
    rasterize(mesh, &screen, |p| rotation * p, width, height, checker)
}

/// The flat colour of a face lit by `shade`.
fn flat(_face: usize, _weights: [f64; 3], shade: f64) -> [u8; 3] {
    [
        (shade * 200.0) as u8,
        (shade * 210.0) as u8,
        (shade * 235.0) as u8,
    ]
}

/// The camera of [`render`]: model → camera rotation and model → screen projection.
fn orthographic(
    frame: &Aabb,
    view: View,
    width: u32,
    height: u32,
) -> (DMat3, impl Fn(DVec3) -> DVec3) {
    let centre = (frame.min + frame.max) * 0.5;
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
    let project = move |p: DVec3| {
        let q = rotation * (p - centre);
        DVec3::new(
            width as f64 * 0.5 + q.x * scale,
            height as f64 * 0.5 - q.y * scale,
            q.z,
        )
    };
    (rotation, project)
}

/// A pinhole camera for [`render_perspective`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub fov_degrees: f64,
}

/// Draws `mesh` flat-shaded as `camera` sees it; faces reaching behind the eye are left out.
pub fn render_perspective(
    mesh: &TriMesh,
    camera: &Perspective,
    width: u32,
    height: u32,
) -> Picture {
    let forward = (camera.target - camera.eye).normalize_or_zero();
    let right = forward.cross(camera.up).normalize_or_zero();
    let up = right.cross(forward);
    let focal = 0.5 * height as f64 / (camera.fov_degrees.to_radians() / 2.0).tan();
    let to_camera = |p: DVec3| {
        let d = p - camera.eye;
        DVec3::new(d.dot(right), d.dot(up), -d.dot(forward))
    };
    // Depth as 1/distance (larger is nearer, linear across the screen); behind the eye: NaN,
    // which the rasterizer skips.
    let screen: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| {
            let q = to_camera(p);
            let z = -q.z;
            if z <= 1e-9 {
                return DVec3::NAN;
            }
            DVec3::new(
                width as f64 * 0.5 + q.x / z * focal,
                height as f64 * 0.5 - q.y / z * focal,
                1.0 / z,
            )
        })
        .collect();
    rasterize(mesh, &screen, to_camera, width, height, flat)
}

/// Fills the faces of `mesh` at their `screen` corners (x, y in pixels, z larger nearer),
/// shaded by their normals in the camera's frame (`to_camera`); `paint` gives a pixel's colour
/// from its face, its corner weights and the face's shade.
fn rasterize(
    mesh: &TriMesh,
    screen: &[DVec3],
    to_camera: impl Fn(DVec3) -> DVec3,
    width: u32,
    height: u32,
    paint: impl Fn(usize, [f64; 3], f64) -> [u8; 3],
) -> Picture {
    let mut depth = vec![f64::NEG_INFINITY; (width * height) as usize];
    let mut pixels = vec![[255u8; 3]; (width * height) as usize];
    let light = DVec3::new(-0.35, 0.45, 1.0).normalize();
    for (face, f) in mesh.faces.iter().enumerate() {
        let [a, b, c] = f.map(|v| screen[v as usize]);
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            continue;
        }
        let world = mesh.corners(*f).map(&to_camera);
        let normal = (world[1] - world[0]).cross(world[2] - world[0]);
        if normal.length_squared() == 0.0 {
            continue;
        }
        let shade = 0.18 + 0.82 * normal.normalize().dot(light).abs();
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
                    pixels[i] = paint(face, [w0, w1, w2], shade);
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

impl Picture {
    /// Writes the picture as a PNG file.
    pub fn save_png(&self, path: &std::path::Path) -> meshcodec::error::Result<()> {
        use plotters::prelude::{BitMapBackend, DrawingBackend};
        let fail = |e: &dyn std::fmt::Display| {
            meshcodec::error::Error::Io(std::io::Error::other(format!("{}: {e}", path.display())))
        };
        let mut backend = BitMapBackend::new(path, (self.width, self.height));
        for (i, px) in self.pixels.iter().enumerate() {
            let (x, y) = (i as u32 % self.width, i as u32 / self.width);
            let colour = plotters::style::RGBColor(px[0], px[1], px[2]);
            backend
                .draw_pixel(
                    (x as i32, y as i32),
                    plotters::style::Color::to_backend_color(&colour),
                )
                .map_err(|e| fail(&e))?;
        }
        backend.present().map_err(|e| fail(&e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checker_shows_its_squares_through_the_uvs() {
        // One square face, seen face-on, whose uvs span two squares a side.
        let mesh = TriMesh::new(
            vec![
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(1.0, -1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let s = 2.0 / CHECKER_SQUARES;
        let uv = [
            DVec2::ZERO,
            DVec2::new(s, 0.0),
            DVec2::new(s, s),
            DVec2::new(0.0, s),
        ];
        let corners = [[uv[0], uv[1], uv[2]], [uv[0], uv[2], uv[3]]];
        let frame = mesh.referenced_bounds().unwrap();
        let picture = render_textured(&mesh, &corners, &frame, View::default(), 64, 64);
        let at = |x: u32, y: u32| picture.pixels[(y * 64 + x) as usize];
        // Diagonal quarters share a colour, neighbouring quarters differ.
        assert_eq!(at(16, 16), at(48, 48));
        assert_eq!(at(48, 16), at(16, 48));
        assert_ne!(at(16, 16), at(48, 16));
        // Without uvs the same mesh is flat-shaded, one colour.
        let flat = render(&mesh, &frame, View::default(), 64, 64);
        assert_eq!(flat.pixels[16 * 64 + 16], flat.pixels[48 * 64 + 48]);
        assert_eq!(flat.pixels[16 * 64 + 16], flat.pixels[16 * 64 + 48]);
    }
}
