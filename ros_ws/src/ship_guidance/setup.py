from glob import glob

from setuptools import find_packages, setup

package_name = 'ship_guidance'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/doc', glob('doc/*.md')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ship Navigation Maintainers',
    maintainer_email='maintainers@shipnav.org',
    description=('Guidance laws (LOS, integral LOS, circular arcs, curved paths, platoon pursuit) '
                 'and the guidance node.'),
    license='MIT',
    entry_points={
        'console_scripts': [
            'guidance_node = ship_guidance.guidance_node:main',
            'follower_node = ship_guidance.follower_node:main',
            'ais_node = ship_guidance.ais_node:main',
            'colav_node = ship_guidance.colav_node:main',
            'nav_display_node = ship_guidance.nav_display_node:main',
            'aivdm_out_node = ship_guidance.aivdm_out_node:main',
            'tracker_node = ship_guidance.tracker_node:main',
        ],
    },
)
