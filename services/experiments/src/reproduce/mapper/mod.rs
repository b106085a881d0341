//! Paper 004 §5 on grid004: the batch experiment ([`experiment`]) against the world's
//! true change rates ([`truth`]), its Fig. 3-like picture ([`plot`]) and the claims
//! judged ([`runner`], `roam reproduce mapper`).

pub mod experiment;
pub mod plot;
pub mod runner;
pub mod truth;
