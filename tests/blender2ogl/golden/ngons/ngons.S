/* ngons.S: bulk arrays of scene ngons, baked by blender2ogl 0.1.0 from ngons_crlf.obj.
   Generated: do not edit. The bytes come from ngons.bin (found through -I<dir>);
   ngons.bin: 680 bytes, fnv1a64 7c98a7ffa50dbd02 */
	.section .rodata.b2o.ngons,"a",@progbits
	.balign 16
	.globl b2o_ngons_positions
	.type b2o_ngons_positions, @object
	.size b2o_ngons_positions, 144
b2o_ngons_positions:
	.incbin "ngons.bin", 0, 144
	.balign 16
	.globl b2o_ngons_normals
	.type b2o_ngons_normals, @object
	.size b2o_ngons_normals, 144
b2o_ngons_normals:
	.incbin "ngons.bin", 144, 144
	.balign 16
	.globl b2o_ngons_texcoords
	.type b2o_ngons_texcoords, @object
	.size b2o_ngons_texcoords, 96
b2o_ngons_texcoords:
	.incbin "ngons.bin", 288, 96
	.balign 16
	.globl b2o_ngons_indices
	.type b2o_ngons_indices, @object
	.size b2o_ngons_indices, 72
b2o_ngons_indices:
	.incbin "ngons.bin", 384, 72
	.balign 16
	.globl b2o_ngons_cloth0_rest_positions
	.type b2o_ngons_cloth0_rest_positions, @object
	.size b2o_ngons_cloth0_rest_positions, 48
b2o_ngons_cloth0_rest_positions:
	.incbin "ngons.bin", 464, 48
	.balign 16
	.globl b2o_ngons_cloth0_mass_vertex_offsets
	.type b2o_ngons_cloth0_mass_vertex_offsets, @object
	.size b2o_ngons_cloth0_mass_vertex_offsets, 20
b2o_ngons_cloth0_mass_vertex_offsets:
	.incbin "ngons.bin", 512, 20
	.balign 16
	.globl b2o_ngons_cloth0_mass_vertices
	.type b2o_ngons_cloth0_mass_vertices, @object
	.size b2o_ngons_cloth0_mass_vertices, 16
b2o_ngons_cloth0_mass_vertices:
	.incbin "ngons.bin", 544, 16
	.balign 16
	.globl b2o_ngons_cloth0_springs
	.type b2o_ngons_cloth0_springs, @object
	.size b2o_ngons_cloth0_springs, 96
b2o_ngons_cloth0_springs:
	.incbin "ngons.bin", 560, 96
	.balign 16
	.globl b2o_ngons_cloth0_triangles
	.type b2o_ngons_cloth0_triangles, @object
	.size b2o_ngons_cloth0_triangles, 24
b2o_ngons_cloth0_triangles:
	.incbin "ngons.bin", 656, 24
	.globl b2o_ngons_bake_458f1accc7c24307
	.type b2o_ngons_bake_458f1accc7c24307, @object
	.size b2o_ngons_bake_458f1accc7c24307, 1
b2o_ngons_bake_458f1accc7c24307:
	.byte 0
	.section .note.GNU-stack,"",@progbits
