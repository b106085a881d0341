//! What is wrong with one field of a scenario's sections: the error every section's
//! check returns, naming the field.

/// A field of a scenario's sections and what is wrong with it, for callers that check
/// a section outside a file (the sim checks parameters given in code the same way).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldIssue {
    /// The field, e.g. `sensing.sigma_toa_m`.
    pub field: String,
    /// What is wrong and what is allowed.
    pub reason: String,
}

impl FieldIssue {
    pub fn new(field: impl Into<String>, reason: impl Into<String>) -> FieldIssue {
        FieldIssue {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
