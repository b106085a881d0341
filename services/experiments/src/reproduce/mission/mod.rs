//! The papers joined. [`missions`]: seeded downtime missions in the built-in world,
//! planned with each coupling and driven in the closed loop; [`runner`] judges the
//! joining claims (`roam reproduce mission`). [`days`]: the executive's whole day in
//! batch (`--days N`).

pub mod days;
pub mod missions;
pub mod runner;
