//! roam's wire contract: every message, every key expression, the codec and the error reply.
//!
//! This crate holds no algorithm and does no I/O. A service and its clients agree on
//! exactly what is here, and nothing else: [`keys`] builds every key expression,
//! [`codec`] turns a message into bytes and back (refusing unknown protocol versions and
//! trailing garbage), [`error`] is the structured reply every failing request gets, and
//! the remaining modules are the message types grouped by the service that owns them.

pub mod bounded;
pub mod cells;
pub mod codec;
pub mod controller;
pub mod error;
pub mod excerpt;
pub mod keys;
pub mod layer_delta;
pub mod localization;
pub mod map;
pub mod mapper;
pub mod mission;
pub mod planner;
pub mod sim;

pub use codec::{decode, encode, DecodeError, Message, PROTOCOL_VERSION};
pub use error::{Cause, ErrorCode, ErrorReply, LimitHit};
pub use excerpt::{excerpt, number, Excerpt, Number};
