//! What can be dropped on the terrain: spheres and boxes of vehicle size,
//! and where each one is after a step.

use rapier3d::prelude::{ColliderBuilder, RigidBodyHandle};

/// A rigid body's shape, in world units (texels; altitude units in z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyShape {
    /// A ball of this radius.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// A box with these half extents along its own x, y, z.
    Box {
        /// Half extents.
        half_extents: [f32; 3],
    },
}

impl BodyShape {
    /// A vehicle-sized ball (a Vangers mechos is some 20-40 texels long).
    pub const VEHICLE_SPHERE: BodyShape = BodyShape::Sphere { radius: 5.0 };
    /// A vehicle-sized box: 16 long, 8 wide, 6 high.
    pub const VEHICLE_BOX: BodyShape = BodyShape::Box {
        half_extents: [8.0, 4.0, 3.0],
    };

    /// Half its height when resting flat (a ball: its radius).
    pub fn half_height(&self) -> f32 {
        match *self {
            BodyShape::Sphere { radius } => radius,
            BodyShape::Box { half_extents } => half_extents[2],
        }
    }

    /// Radius of the sphere around it.
    pub fn bounding_radius(&self) -> f32 {
        match *self {
            BodyShape::Sphere { radius } => radius,
            BodyShape::Box {
                half_extents: [a, b, c],
            } => (a * a + b * b + c * c).sqrt(),
        }
    }

    /// Checks the sizes are positive and finite (the message names the value).
    pub fn validate(&self) -> Result<(), crate::PhysicsError> {
        let sizes: &[f32] = match self {
            BodyShape::Sphere { radius } => std::slice::from_ref(radius),
            BodyShape::Box { half_extents } => half_extents,
        };
        match sizes.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            Some(bad) => Err(crate::PhysicsError::BadSize(*self, *bad)),
            None => Ok(()),
        }
    }

    pub(crate) fn collider(&self) -> ColliderBuilder {
        match *self {
            BodyShape::Sphere { radius } => ColliderBuilder::ball(radius),
            BodyShape::Box {
                half_extents: [a, b, c],
            } => ColliderBuilder::cuboid(a, b, c),
        }
    }
}

/// A dropped body, as [`crate::TerrainPhysics::drop_body`] returned it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BodyId(pub(crate) RigidBodyHandle);

/// Where a body is: for drawing it and for tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPose {
    /// Which body.
    pub id: BodyId,
    /// Its shape.
    pub shape: BodyShape,
    /// Centre in world coordinates, inside the map (`x` in
    /// `[0.5, width + 0.5)`, likewise `y`: bodies wrap around the torus).
    pub position: [f32; 3],
    /// Rotation as a unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
    /// Velocity, units per second.
    pub velocity: [f32; 3],
    /// Whether rapier has put it to sleep (at rest).
    pub sleeping: bool,
}
