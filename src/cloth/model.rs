//! The static part of a cloth: topology, rest lengths, masses, pins.

use glam::{Vec2, Vec3};

use crate::mesh::{ClothMesh, SpringKind};

use super::adjacency::Adjacency;
use super::edge_colours::EdgeColours;
use super::springs::Springs;

/// How a cloth's mass is shared among its particles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MassDistribution {
    /// Each triangle gives a third of its mass to each corner (with a floor; see
    /// [`ClothModel::set_density`]).
    #[default]
    Lumped,
    /// Every particle weighs the same: the cloth's mass over the particle count.
    Uniform,
}

/// Smallest particle mass, as a fraction of the mean particle mass.
pub const MASS_FLOOR: f32 = 0.1;

/// Topology and rest state of a cloth, shared by every step. Pins are particles with
/// inverse mass 0.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothModel {
    pub rest_positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub triangles: Vec<[u32; 3]>,
    pub springs: Springs,
    /// How many unique edges the triangulated mesh has (the first springs).
    pub mesh_edges: usize,
    /// How many springs are bend springs (the last ones).
    pub bend_springs: usize,
    /// Interior edges as hinges `[x0, x1, a, b]` (see [`ClothMesh::hinges`]).
    pub hinges: Vec<[u32; 4]>,
    /// Which springs meet at each particle.
    pub adjacency: Adjacency,
    /// The structural and shear springs in colours: the order contacts with an obstacle's
    /// sharp edges take them in, on either backend.
    pub edge_colours: EdgeColours,
    /// Particle mass, kg (lumped from areal density by triangle area).
    pub mass: Vec<f32>,
    /// 1/mass, 1/kg; 0 for pinned particles.
    pub inv_mass: Vec<f32>,
    /// Pinned particle indices, sorted and unique.
    pub pins: Vec<u32>,
    /// Areal density the masses came from, kg/m².
    pub density: f32,
    /// How the mass is shared among the particles.
    pub masses: MassDistribution,
}

impl ClothModel {
    /// Builds a model from a mesh with areal density `density` (kg/m²): each triangle gives a
    /// third of its mass to each corner. `pins` (out-of-range indices ignored) get inverse
    /// mass 0.
    pub fn new(mesh: &ClothMesh, density: f32, pins: &[u32]) -> Self {
        let n = mesh.positions.len();
        let mut springs = Springs::default();
        for ([a, b], kind) in mesh.springs() {
            springs.a.push(a);
            springs.b.push(b);
            springs
                .rest
                .push(mesh.positions[a as usize].distance(mesh.positions[b as usize]));
            springs.kind.push(kind);
        }
        let edges = springs.len() - mesh.bend_pairs.len();
        let mut model = Self {
            adjacency: Adjacency::new(n, &springs),
            edge_colours: EdgeColours::of(n, &springs, edges),
            rest_positions: mesh.positions.clone(),
            uvs: mesh.uvs.clone(),
            triangles: mesh.triangles.clone(),
            bend_springs: mesh.bend_pairs.len(),
            springs,
            mesh_edges: mesh.edges.len(),
            hinges: mesh.hinges.clone(),
            mass: vec![0.0; n],
            inv_mass: vec![0.0; n],
            pins: Vec::new(),
            density,
            masses: MassDistribution::Lumped,
        };
        model.set_density(density);
        model.set_pins(pins);
        model
    }

    /// A model of point masses joined by `springs`, without triangles (chains, oscillators,
    /// tests). `mass` is per particle, kg; `pins` get inverse mass 0.
    pub fn from_springs(
        rest_positions: Vec<Vec3>,
        springs: Springs,
        mass: Vec<f32>,
        pins: &[u32],
    ) -> Self {
        let n = rest_positions.len();
        let bend = (springs.kind.iter())
            .filter(|k| **k == SpringKind::Bend)
            .count();
        let mut model = Self {
            adjacency: Adjacency::new(n, &springs),
            edge_colours: EdgeColours::of(n, &springs, springs.len() - bend),
            uvs: vec![Vec2::ZERO; n],
            triangles: Vec::new(),
            mesh_edges: 0,
            bend_springs: bend,
            hinges: Vec::new(),
            springs,
            rest_positions,
            inv_mass: vec![0.0; n],
            mass,
            pins: Vec::new(),
            density: 0.0,
            masses: MassDistribution::Lumped,
        };
        model.set_pins(pins);
        model
    }

    pub fn particle_count(&self) -> usize {
        self.rest_positions.len()
    }

    /// The mesh edges' rest lengths, metres (the first springs).
    pub fn edge_rest_lengths(&self) -> &[f32] {
        &self.springs.rest[..self.mesh_edges.min(self.springs.len())]
    }

    /// The index of the first bend spring (the bend springs are the last ones).
    pub fn bend_start(&self) -> usize {
        self.springs.len() - self.bend_springs
    }

    /// Recomputes masses from an areal density, kg/m²: each triangle gives a third of its
    /// mass to each corner; then every particle is raised to at least [`MASS_FLOOR`] of the
    /// mean particle mass and all are rescaled to keep the total ρ·A. (A vertex that only
    /// sliver triangles touch would otherwise be so light that no step could follow its
    /// spring's vibration; on a regular grid the lightest corner carries 1/6 of the mean,
    /// above the floor, so nothing changes there.)
    pub fn set_density(&mut self, density: f32) {
        self.density = density;
        self.mass.iter_mut().for_each(|m| *m = 0.0);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.rest_positions[i as usize]);
            let third = density * 0.5 * (b - a).cross(c - a).length() / 3.0;
            for &i in t {
                self.mass[i as usize] += third;
            }
        }
        // Summed in f64: in f32 the 700 × 700 cloth's masses lost 0.4 % to rounding (each
        // addend is a few dozen ulps of the running total near 1 kg).
        let total = sum_f64(&self.mass);
        if self.masses == MassDistribution::Uniform {
            let each = total / self.mass.len().max(1) as f32;
            self.mass.iter_mut().for_each(|m| *m = each);
        } else if total > 0.0 {
            let floor = MASS_FLOOR * total / self.mass.len() as f32;
            self.mass.iter_mut().for_each(|m| *m = m.max(floor));
            let scale = total / sum_f64(&self.mass);
            self.mass.iter_mut().for_each(|m| *m *= scale);
        }
        let pins = std::mem::take(&mut self.pins);
        self.set_pins(&pins);
    }

    /// Shares the mass as `masses` says (recomputed from the current density).
    pub fn set_mass_distribution(&mut self, masses: MassDistribution) {
        self.masses = masses;
        self.set_density(self.density);
    }

    /// Replaces the pin set; pinned particles get inverse mass 0, the rest 1/mass.
    pub fn set_pins(&mut self, pins: &[u32]) {
        let n = self.particle_count();
        self.pins = pins.iter().copied().filter(|&p| (p as usize) < n).collect();
        self.pins.sort_unstable();
        self.pins.dedup();
        for (w, &m) in self.inv_mass.iter_mut().zip(&self.mass) {
            *w = if m > 0.0 { 1.0 / m } else { 0.0 };
        }
        for &p in &self.pins {
            self.inv_mass[p as usize] = 0.0;
        }
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> f32 {
        sum_f64(&self.mass)
    }
}

/// The sum of `values`, accumulated in f64.
fn sum_f64(values: &[f32]) -> f32 {
    values.iter().map(|&v| f64::from(v)).sum::<f64>() as f32
}
