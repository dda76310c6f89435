/* grid.S: bulk arrays of scene grid, baked by blender2ogl 0.1.0 from grid.obj.
   Generated: do not edit. The bytes come from grid.bin (found through -I<dir>);
   grid.bin: 1400 bytes, fnv1a64 877821939f437456 */
	.section .rodata.b2o.grid,"a",@progbits
	.balign 16
	.globl b2o_grid_positions
	.type b2o_grid_positions, @object
	.size b2o_grid_positions, 156
b2o_grid_positions:
	.incbin "grid.bin", 0, 156
	.balign 16
	.globl b2o_grid_normals
	.type b2o_grid_normals, @object
	.size b2o_grid_normals, 156
b2o_grid_normals:
	.incbin "grid.bin", 160, 156
	.balign 16
	.globl b2o_grid_texcoords
	.type b2o_grid_texcoords, @object
	.size b2o_grid_texcoords, 104
b2o_grid_texcoords:
	.incbin "grid.bin", 320, 104
	.balign 16
	.globl b2o_grid_indices
	.type b2o_grid_indices, @object
	.size b2o_grid_indices, 120
b2o_grid_indices:
	.incbin "grid.bin", 432, 120
	.balign 16
	.globl b2o_grid_texture0
	.type b2o_grid_texture0, @object
	.size b2o_grid_texture0, 81
b2o_grid_texture0:
	.incbin "grid.bin", 560, 81
	.balign 16
	.globl b2o_grid_cloth0_rest_positions
	.type b2o_grid_cloth0_rest_positions, @object
	.size b2o_grid_cloth0_rest_positions, 108
b2o_grid_cloth0_rest_positions:
	.incbin "grid.bin", 656, 108
	.balign 16
	.globl b2o_grid_cloth0_mass_vertex_offsets
	.type b2o_grid_cloth0_mass_vertex_offsets, @object
	.size b2o_grid_cloth0_mass_vertex_offsets, 40
b2o_grid_cloth0_mass_vertex_offsets:
	.incbin "grid.bin", 768, 40
	.balign 16
	.globl b2o_grid_cloth0_mass_vertices
	.type b2o_grid_cloth0_mass_vertices, @object
	.size b2o_grid_cloth0_mass_vertices, 36
b2o_grid_cloth0_mass_vertices:
	.incbin "grid.bin", 816, 36
	.balign 16
	.globl b2o_grid_cloth0_vertex_mass
	.type b2o_grid_cloth0_vertex_mass, @object
	.size b2o_grid_cloth0_vertex_mass, 36
b2o_grid_cloth0_vertex_mass:
	.incbin "grid.bin", 864, 36
	.balign 16
	.globl b2o_grid_cloth0_springs
	.type b2o_grid_cloth0_springs, @object
	.size b2o_grid_cloth0_springs, 384
b2o_grid_cloth0_springs:
	.incbin "grid.bin", 912, 384
	.balign 16
	.globl b2o_grid_cloth0_triangles
	.type b2o_grid_cloth0_triangles, @object
	.size b2o_grid_cloth0_triangles, 96
b2o_grid_cloth0_triangles:
	.incbin "grid.bin", 1296, 96
	.balign 16
	.globl b2o_grid_cloth0_pins
	.type b2o_grid_cloth0_pins, @object
	.size b2o_grid_cloth0_pins, 8
b2o_grid_cloth0_pins:
	.incbin "grid.bin", 1392, 8
	.globl b2o_grid_bake_61e2c840d54b2dd6
	.type b2o_grid_bake_61e2c840d54b2dd6, @object
	.size b2o_grid_bake_61e2c840d54b2dd6, 1
b2o_grid_bake_61e2c840d54b2dd6:
	.byte 0
	.section .note.GNU-stack,"",@progbits
