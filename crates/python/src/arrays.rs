//! Images between pathlight's [`Film`] and NumPy: float32 arrays of shape (height, width, 3),
//! row 0 at the top, linear RGB.

use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3, PyUntypedArrayMethods};
use pathlight_core::Film;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `film` as a new array.
pub fn to_numpy<'py>(py: Python<'py>, film: &Film) -> Bound<'py, PyArray3<f32>> {
    let values: Vec<f32> = film.pixels.iter().flatten().copied().collect();
    let shape = (film.height as usize, film.width as usize, 3);
    Array3::from_shape_vec(shape, values)
        .expect("a film holds width x height pixels")
        .into_pyarray(py)
}

/// The image `array` (named `name` in errors) as a film of one sample per pixel.
pub fn from_numpy(name: &str, array: &PyReadonlyArray3<f32>) -> PyResult<Film> {
    let &[height, width, channels] = array.shape() else {
        unreachable!("a three-dimensional array has three extents")
    };
    if channels != 3 || height == 0 || width == 0 {
        return Err(PyValueError::new_err(format!(
            "{name} has shape ({height}, {width}, {channels}): an image is (height, width, 3)"
        )));
    }
    let (Ok(width32), Ok(height32)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(PyValueError::new_err(format!("{name} is too large")));
    };
    let view = array.as_array();
    let pixels = (0..height)
        .flat_map(|y| (0..width).map(move |x| (y, x)))
        .map(|(y, x)| [view[[y, x, 0]], view[[y, x, 1]], view[[y, x, 2]]])
        .collect();
    Ok(Film {
        width: width32,
        height: height32,
        spp: 1,
        pixels,
    })
}
