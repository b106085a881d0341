//! A tunable parameter outside its range: the one error the planner's GA parameters and
//! the controller's APF parameters give, so a client learns which parameter, what it
//! sent and what to use, in the same words from either service.

/// A parameter outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("parameter {name} = {} is out of range; use {range}", roam_proto::number(*.value))]
pub struct ParamError {
    pub name: &'static str,
    pub value: f64,
    /// What to use, in words (`"(0, 1]"`, `"a positive number of metres"`).
    pub range: &'static str,
}

/// `Ok` when `ok` holds and `value` is finite; otherwise the [`ParamError`] naming it.
pub fn check_param(
    name: &'static str,
    value: f64,
    ok: bool,
    range: &'static str,
) -> Result<(), ParamError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ParamError { name, value, range })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parameter_out_of_range_or_not_finite_is_named_with_what_to_use() {
        assert_eq!(check_param("w1", 0.5, true, "[0, 1]"), Ok(()));
        let e = check_param("w1", 1e300, false, "[0, 1]").expect_err("out of range");
        assert_eq!(
            e.to_string(),
            "parameter w1 = 1e300 is out of range; use [0, 1]"
        );
        assert!(check_param("z", f64::NAN, true, "any finite number").is_err());
    }
}
