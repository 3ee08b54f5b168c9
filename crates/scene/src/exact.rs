//! Fixed-size arrays read exactly: `[1, 2, 3, 4]` where three numbers are wanted is an error
//! naming the length, not three numbers and a dropped fourth (what the TOML deserializer
//! does with plain Rust arrays). Used by the `desc` structs with `deserialize_with`.

use serde::de::{Deserialize, Deserializer, Error};

/// What an array of `N` values is called in error messages.
fn expected<const N: usize>() -> String {
    format!("an array of {N} numbers")
}

/// `[T; N]` from an array of exactly `N` values.
pub fn array<'de, D, T, const N: usize>(deserializer: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let values = Vec::<T>::deserialize(deserializer)?;
    let len = values.len();
    values
        .try_into()
        .map_err(|_| D::Error::invalid_length(len, &expected::<N>().as_str()))
}

/// An optional `[T; N]` (the field needs `#[serde(default)]` as well).
pub fn optional_array<'de, D, T, const N: usize>(
    deserializer: D,
) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    array(deserializer).map(Some)
}

/// A list of `[T; N]`, each exactly `N` long.
pub fn array_list<'de, D, T, const N: usize>(deserializer: D) -> Result<Vec<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Vec::<Vec<T>>::deserialize(deserializer)?
        .into_iter()
        .map(|values| {
            let len = values.len();
            values
                .try_into()
                .map_err(|_| D::Error::invalid_length(len, &expected::<N>().as_str()))
        })
        .collect()
}
