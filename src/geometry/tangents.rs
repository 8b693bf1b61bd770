//! MikkTSpace tangents (glTF 2.0 section 3.7.2.1: a normal-mapped primitive without TANGENT gets them "using
//! default MikkTSpace algorithms with the specified vertex positions, normals, and texture coordinates
//! associated with the normal texture"), by Bevy's port of the reference implementation.
//!
//! MikkTSpace's bitangent is the direction in which v grows, with v up (OpenGL's texture origin, Blender's);
//! glTF's texture origin is the top-left corner and its normal textures' +Y points up the image, towards smaller
//! v. MikkTSpace is therefore given (u, 1 - v), as Blender's exporter computes the tangents it writes, so that the
//! bitangent cross(normal, tangent) x w points up the image, as the glTF Sample Viewer and three.js read it.

/// A triangle list as MikkTSpace reads it, and the tangent it writes per corner.
struct Faces<'a> {
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    uvs: &'a [[f32; 2]],
    indices: &'a [u32],
    corners: Vec<[f32; 4]>,
}

impl bevy_mikktspace::Geometry for Faces<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.indices[face * 3 + vert] as usize]
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.indices[face * 3 + vert] as usize]
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let [u, v] = self.uvs[self.indices[face * 3 + vert] as usize];
        [u, 1.0 - v]
    }

    /// A corner MikkTSpace found no tangent for gets its default (+x, the bitangent's sign -1), as the reference
    /// implementation and bevy_mikktspace 0.16 wrote it.
    fn set_tangent(
        &mut self,
        tangent: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        self.corners[face * 3 + vert] = tangent.unwrap_or_default().tangent_encoded();
    }
}

/// Per corner of `indices` (one entry per index), the MikkTSpace tangent: xyz, and w the bitangent's sign
/// (bitangent = cross(normal, tangent) x w, as glTF's TANGENT). None when MikkTSpace cannot make them (no
/// triangles).
pub fn mikktspace_corners(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    uvs: &[[f32; 2]],
    indices: &[u32],
) -> Option<Vec<[f32; 4]>> {
    let mut faces = Faces {
        positions,
        normals,
        uvs,
        indices,
        corners: vec![[1.0, 0.0, 0.0, 1.0]; indices.len()],
    };
    bevy_mikktspace::generate_tangents(&mut faces)
        .is_ok()
        .then_some(faces.corners)
}

/// Whether two corner tangents are the same vertex's (direction within about 0.06 degrees, same sign).
pub fn same_tangent(a: [f32; 4], b: [f32; 4]) -> bool {
    a[3] == b[3] && (0..3).all(|i| (a[i] - b[i]).abs() <= 1e-3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad in the xy plane with its image upright (u along +x, v along -y: glTF's texture origin at the
    /// top-left): the tangent is +x and the bitangent cross(n, t) x w = +y, up the image, so w = 1; mirroring u
    /// turns the tangent to -x and the sign with it.
    #[test]
    fn a_quad_gets_its_u_direction() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let normals = [[0.0, 0.0, 1.0]; 4];
        let uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
        let indices = [0, 1, 2, 0, 2, 3];
        let t = mikktspace_corners(&positions, &normals, &uvs, &indices).unwrap();
        for c in &t {
            assert!((c[0] - 1.0).abs() < 1e-5 && c[1].abs() < 1e-5, "{c:?}");
            // cross(+z, +x) = +y, up the image (v decreasing): w = 1.
            assert_eq!(c[3], 1.0);
        }
        let mirrored = uvs.map(|[u, v]| [1.0 - u, v]);
        let t = mikktspace_corners(&positions, &normals, &mirrored, &indices).unwrap();
        assert!(
            t.iter().all(|c| (c[0] + 1.0).abs() < 1e-5 && c[3] == -1.0),
            "{t:?}"
        );
        assert!(same_tangent(t[0], t[3]));
        assert!(!same_tangent(t[0], [1.0, 0.0, 0.0, t[0][3]]));
    }
}
