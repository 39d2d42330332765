//! Helpers shared by the test modules.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{library, stack, ChordTolerance, Design, ParamError};

/// Every library design and every preset of each.
pub fn library_designs_and_presets() -> Vec<Design> {
    let mut designs = Vec::new();
    for (name, _) in library::LIBRARY {
        let base = library::load(name).unwrap();
        for p in base.presets.keys() {
            designs.push(base.with_preset(p).unwrap());
        }
        designs.push(base);
    }
    designs
}

/// The errors of `validate` for `d` at the default tolerance (empty when valid).
pub fn validation_errors(d: &Design) -> Vec<ParamError> {
    let materials = MaterialsTable::embedded().unwrap();
    match stack::validate(d, &materials, ChordTolerance::default()) {
        Ok(_) => Vec::new(),
        Err(e) => e.0,
    }
}
