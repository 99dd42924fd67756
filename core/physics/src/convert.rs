//! Between our glam (0.30) and rapier's (0.33): the same layouts, different crates.

use rapier3d::math::{Pose, Rotation, Vector};

pub fn to_rapier(v: glam::Vec3) -> Vector {
    Vector::from_array(v.to_array())
}

pub fn from_rapier(v: Vector) -> glam::Vec3 {
    glam::Vec3::from_array(v.to_array())
}

pub fn quat_to_rapier(q: glam::Quat) -> Rotation {
    Rotation::from_array(q.to_array())
}

pub fn quat_from_rapier(q: Rotation) -> glam::Quat {
    glam::Quat::from_array(q.to_array())
}

pub fn pose(translation: glam::Vec3, rotation: glam::Quat) -> Pose {
    Pose::from_parts(to_rapier(translation), quat_to_rapier(rotation))
}
