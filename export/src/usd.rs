//! The assembled sensor as a USD layer (issue 103): `sim/<design>.usda`, for Isaac Sim / Isaac
//! Lab and any USD reader, beside the files of [`crate::sim::files`].
//!
//! - The stage is in metres and kilograms (`metersPerUnit = 1`, `kilogramsPerUnit = 1`), z up.
//! - The default prim, named after the design, is an Xform in the sensor frame
//!   (docs/conventions.md) with UsdPhysics' RigidBodyAPI and MassAPI: `physics:mass`,
//!   `physics:centerOfMass`, and the inertia tensor ([`crate::mass::SensorMass`]) as
//!   `physics:diagonalInertia` (its eigenvalues) in `physics:principalAxes` (the rotation whose
//!   columns are its eigenvectors, a quaternion).
//! - Each member is a Mesh (its written mesh, in metres, triangles, `extent`, display colour and
//!   opacity); the skin ([`crate::sim::skin_member`]) carries CollisionAPI and
//!   MeshCollisionAPI (convex hull), the others are visual; each printed housing member collides
//!   as a Cylinder or a scaled Cube round it (purpose `guide`, [`crate::sim::housing_shapes`]).
//! - `camera`, when the design places one: a Camera prim (USD's x right, y up, looking along -z:
//!   the OpenCV frame turned about x) whose `focalLength` over `horizontalAperture` is the
//!   pinhole's focal length over the image width (square pixels, the principal point at the
//!   image's centre), with the same note as the MJCF's camera; `contact_surface` an Xform on the
//!   skin's top; the LEDs as SphereLights shaped to their cone, emitting along their -z.

use std::fmt::Write as _;

use fabkit_designs::geometry::Mesh;
use nalgebra::{Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

use crate::manifest::ManifestMember;
use crate::mass::SensorMass;
use crate::sim::{escape, num, rgba, skin_member, HousingShape, SimScene};

/// The principal moments (ascending) and the rotation whose columns are the principal axes (a
/// right-handed frame) of the symmetric tensor `i`.
pub fn principal(i: [[f64; 3]; 3]) -> ([f64; 3], UnitQuaternion<f64>) {
    let m = Matrix3::from_fn(|r, c| i[r][c]);
    let e = SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let mut axes = Matrix3::from_columns(&order.map(|k| e.eigenvectors.column(k).into_owned()));
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(axes));
    (order.map(|k| e.eigenvalues[k]), q)
}

/// A USD string's text: no double quote or backslash (USD's string delimiters and escape).
fn text(s: &str) -> String {
    s.replace('\\', "/").replace('"', "'")
}

fn tuple(v: [f64; 3]) -> String {
    format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]))
}

/// A USD `matrix4d` (row vectors: the rows are the local axes in the parent's frame, then the
/// translation) of a frame whose axes are `x`, `y`, `z` at `t`.
fn matrix(x: Vector3<f64>, y: Vector3<f64>, z: Vector3<f64>, t: [f64; 3]) -> String {
    format!(
        "( ({}, {}, {}, 0), ({}, {}, {}, 0), ({}, {}, {}, 0), ({}, {}, {}, 1) )",
        num(x[0]),
        num(x[1]),
        num(x[2]),
        num(y[0]),
        num(y[1]),
        num(y[2]),
        num(z[0]),
        num(z[1]),
        num(z[2]),
        num(t[0]),
        num(t[1]),
        num(t[2])
    )
}

/// The USD layer of `design`'s assembled sensor (see the module docs): `members` with their
/// written `meshes` (mm), its `mass` and `scene`; `header` for the layer's `doc`.
pub fn layer(
    design: &str,
    header: &str,
    members: &[ManifestMember],
    meshes: &[Mesh],
    mass: &SensorMass,
    scene: &SimScene,
) -> String {
    const MM: f64 = 1e-3;
    let d = escape(design);
    let mut x = String::new();
    let _ = writeln!(x, "#usda 1.0");
    let _ = writeln!(x, "(");
    let doc = crate::sim::intro(header, "one rigid body", members, mass, scene);
    let _ = writeln!(x, "    doc = \"\"\"{}\"\"\"", text(&doc.join("\n")));
    let _ = writeln!(x, "    defaultPrim = \"{d}\"");
    let _ = writeln!(x, "    metersPerUnit = 1");
    let _ = writeln!(x, "    kilogramsPerUnit = 1");
    let _ = writeln!(x, "    upAxis = \"Z\"");
    let _ = writeln!(x, ")");
    let _ = writeln!(x);
    let _ = writeln!(
        x,
        "def Xform \"{d}\" (\n    prepend apiSchemas = [\"PhysicsRigidBodyAPI\", \"PhysicsMassAPI\"]\n)\n{{"
    );
    let (moments, axes) = principal(mass.inertia_g_mm2);
    let _ = writeln!(x, "    float physics:mass = {}", num(mass.mass_g * 1e-3));
    let _ = writeln!(
        x,
        "    point3f physics:centerOfMass = {}",
        tuple(mass.centre_of_mass_mm.map(|v| v * MM))
    );
    // g mm^2 = 1e-9 kg m^2
    let _ = writeln!(
        x,
        "    float3 physics:diagonalInertia = {}",
        tuple(moments.map(|v| v * 1e-9))
    );
    let _ = writeln!(
        x,
        "    quatf physics:principalAxes = ({}, {}, {}, {})",
        num(axes.w),
        num(axes.i),
        num(axes.j),
        num(axes.k)
    );
    let skin = skin_member(members);
    for (k, (m, mesh)) in members.iter().zip(meshes).enumerate() {
        let collision = if Some(k) == skin {
            " (\n        prepend apiSchemas = [\"PhysicsCollisionAPI\", \"PhysicsMeshCollisionAPI\"]\n    )"
        } else {
            ""
        };
        let _ = writeln!(x);
        let _ = writeln!(x, "    def Mesh \"{}\"{collision}\n    {{", escape(&m.name));
        if Some(k) == skin {
            let _ = writeln!(
                x,
                "        uniform token physics:approximation = \"convexHull\""
            );
        }
        let _ = writeln!(x, "        uniform token subdivisionScheme = \"none\"");
        let b = m.bbox_mm;
        let _ = writeln!(
            x,
            "        float3[] extent = [{}, {}]",
            tuple(b.min.map(|v| v * MM)),
            tuple(b.max.map(|v| v * MM))
        );
        let _ = write!(x, "        int[] faceVertexCounts = [");
        for i in 0..mesh.triangles.len() {
            let _ = write!(x, "{}3", if i == 0 { "" } else { ", " });
        }
        let _ = writeln!(x, "]");
        let _ = write!(x, "        int[] faceVertexIndices = [");
        for (i, t) in mesh.triangles.iter().enumerate() {
            let _ = write!(
                x,
                "{}{}, {}, {}",
                if i == 0 { "" } else { ", " },
                t[0],
                t[1],
                t[2]
            );
        }
        let _ = writeln!(x, "]");
        let _ = write!(x, "        point3f[] points = [");
        for (i, v) in mesh.vertices.iter().enumerate() {
            let _ = write!(
                x,
                "{}{}",
                if i == 0 { "" } else { ", " },
                tuple(v.map(|c| c * MM))
            );
        }
        let _ = writeln!(x, "]");
        let c: Vec<&str> = rgba(m).split(' ').collect();
        let _ = writeln!(
            x,
            "        color3f[] primvars:displayColor = [({}, {}, {})]",
            c[0], c[1], c[2]
        );
        let _ = writeln!(x, "        float[] primvars:displayOpacity = [{}]", c[3]);
        let _ = writeln!(x, "    }}");
    }
    for (h, shape) in crate::sim::housing_shapes(members) {
        let _ = writeln!(x);
        let (prim, attrs, c) = match shape {
            HousingShape::Cylinder(r, height, c) => (
                "Cylinder",
                format!(
                    "        uniform token axis = \"Z\"\n        double radius = {}\n        double height = {}",
                    num(r * MM),
                    num(height * MM)
                ),
                c,
            ),
            HousingShape::Box(half, c) => (
                "Cube",
                // a unit-size cube scaled to the box
                format!(
                    "        double size = 1\n        float3 xformOp:scale = {}",
                    tuple(half.map(|v| 2.0 * v * MM))
                ),
                c,
            ),
        };
        let order = if prim == "Cube" {
            "[\"xformOp:translate\", \"xformOp:scale\"]"
        } else {
            "[\"xformOp:translate\"]"
        };
        let _ = writeln!(
            x,
            "    def {prim} \"{}_collision\" (\n        prepend apiSchemas = [\"PhysicsCollisionAPI\"]\n    )\n    {{\n        uniform token purpose = \"guide\"\n{attrs}\n        double3 xformOp:translate = {}\n        uniform token[] xformOpOrder = {order}\n    }}",
            escape(&h.name),
            tuple(c.map(|v| v * MM))
        );
    }
    if let Some(c) = &scene.camera {
        let r = c.t_sensor_cam.rotation.to_rotation_matrix();
        let (ex, ey, ez) = (
            r.matrix().column(0).into_owned(),
            r.matrix().column(1).into_owned(),
            r.matrix().column(2).into_owned(),
        );
        // any aperture: the projection is focalLength / horizontalAperture x width
        let aperture = 20.955;
        let _ = writeln!(x);
        let _ = writeln!(
            x,
            "    def Camera \"camera\" (\n        doc = \"{}\"\n    )\n    {{",
            text(&c.what)
        );
        let _ = writeln!(
            x,
            "        matrix4d xformOp:transform = {}",
            matrix(
                ex,
                -ey,
                -ez,
                c.t_sensor_cam.translation.vector.map(|v| v * MM).into()
            )
        );
        let _ = writeln!(
            x,
            "        uniform token[] xformOpOrder = [\"xformOp:transform\"]"
        );
        let _ = writeln!(x, "        token projection = \"perspective\"");
        let _ = writeln!(
            x,
            "        float focalLength = {}",
            num(c.fy_px / f64::from(c.width_px) * aperture)
        );
        let _ = writeln!(x, "        float horizontalAperture = {}", num(aperture));
        let _ = writeln!(
            x,
            "        float verticalAperture = {}",
            num(aperture * f64::from(c.height_px) / f64::from(c.width_px))
        );
        let _ = writeln!(x, "        float2 clippingRange = (0.0001, 10)");
        let _ = writeln!(x, "    }}");
    }
    if let Some(s) = skin {
        let b = members[s].bbox_mm;
        let top = [
            (b.min[0] + b.max[0]) / 2.0 * MM,
            (b.min[1] + b.max[1]) / 2.0 * MM,
            b.max[2] * MM,
        ];
        let _ = writeln!(x);
        let _ = writeln!(
            x,
            "    def Xform \"contact_surface\"\n    {{\n        double3 xformOp:translate = {}\n        uniform token[] xformOpOrder = [\"xformOp:translate\"]\n    }}",
            tuple(top)
        );
    }
    for (k, l) in scene.lights.iter().enumerate() {
        // the light's -z along its beam
        let z = -Vector3::from(l.direction).normalize();
        let helper = if z.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let xa = helper.cross(&z).normalize();
        let ya = z.cross(&xa);
        let _ = writeln!(x);
        let _ = writeln!(
            x,
            "    def SphereLight \"led_{}\" (\n        prepend apiSchemas = [\"ShapingAPI\"]\n    )\n    {{",
            k + 1
        );
        let _ = writeln!(
            x,
            "        matrix4d xformOp:transform = {}",
            matrix(xa, ya, z, l.position_mm.map(|v| v * MM))
        );
        let _ = writeln!(
            x,
            "        uniform token[] xformOpOrder = [\"xformOp:transform\"]"
        );
        let _ = writeln!(x, "        float inputs:radius = 0.0005");
        let _ = writeln!(x, "        color3f inputs:color = {}", tuple(l.colour_rgb));
        let _ = writeln!(
            x,
            "        float inputs:shaping:cone:angle = {}",
            num(l.cone_half_angle_deg)
        );
        let _ = writeln!(x, "    }}");
    }
    let _ = writeln!(x, "}}");
    x
}
