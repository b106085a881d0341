//! The papers joined. [`missions`]: seeded downtime missions in the built-in world,
//! planned with each coupling and driven in the closed loop; [`runner`] judges the
//! joining claims (`roam reproduce mission`). [`days`]: the executive's whole day in
//! batch (`--days N`). [`todays_plans`]: what today's executive would have planned in
//! a window, the demo's comparison.

pub mod days;
pub mod missions;
pub mod runner;
pub mod todays_plans;
