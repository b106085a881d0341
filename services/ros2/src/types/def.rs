//! What a definition is made of: a message's fields, each with its element type and
//! shape, and the two shorthands the tables write fields with.

/// A field's element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Base {
    Int8,
    Uint8,
    Uint16,
    Int32,
    Uint32,
    Int64,
    Uint64,
    Float32,
    Float64,
    Bool,
    String,
    /// A `char` in a `.msg` file: rosidl maps it to an 8-bit unsigned integer.
    Char,
    /// Another message, by its full name (`geometry_msgs/msg/Pose`).
    Nested(&'static str),
}

/// Single, fixed array, bounded or unbounded sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Single,
    Array(u32),
    Bounded(u32),
    Unbounded,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub base: Base,
    pub shape: Shape,
}

/// A message: its full name (`pkg/msg/Name`, or `pkg/srv/Name_Request` for a service's
/// parts) and its fields in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MsgDef {
    pub name: &'static str,
    pub fields: &'static [Field],
}

pub(super) const fn f(name: &'static str, base: Base) -> Field {
    Field {
        name,
        base,
        shape: Shape::Single,
    }
}

pub(super) const fn shaped(name: &'static str, base: Base, shape: Shape) -> Field {
    Field { name, base, shape }
}
