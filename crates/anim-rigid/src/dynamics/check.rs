//! The argument checks shared by the dynamics algorithms: the lengths of `q`, `v` and the
//! other joint-space vectors against the model, and a [`Data`] made for that model.

use crate::data::Data;
use crate::model::Model;

#[track_caller]
pub(crate) fn check_q(model: &Model, data: &Data, q: &[f64]) {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
}

#[track_caller]
pub(crate) fn check_v(model: &Model, name: &str, v: &[f64]) {
    assert_eq!(v.len(), model.nv(), "{name} has length {}, the model nv = {}", v.len(), model.nv());
}
