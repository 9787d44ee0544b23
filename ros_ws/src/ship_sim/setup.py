from glob import glob

from setuptools import find_packages, setup

package_name = 'ship_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    # RAO tables of ship_sim.environment.wave_rao (scripts/make_rao_tables.py writes them)
    package_data={'ship_sim.environment': ['data/*.npz']},
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
    description=('Vessel plant models (Mariner, Esso tanker, container ship, Nomoto, NPS AUV II), ocean current, wind, '
                 'and the vessel simulator node.'),
    license='MIT',
    entry_points={
        'console_scripts': [
            'vessel_node = ship_sim.vessel_node:main',
            'traffic_node = ship_sim.traffic_node:main',
        ],
    },
)
